#include "gpu/gpu_fluid.h"

#include <algorithm>
#include <cmath>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "core/multigrid.h"
#include "fluid/fluid_step.h"
#include "fluid/pressure_projection.h"
#include "fluid/smoke.h"
#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_multigrid.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"
#include "gpu/gpu_reduction.h"
#include "gpu/gpu_stage_timer.h"
#include "gpu/kernel_modes.h"

namespace morphoflow {

// Component a's implicit viscous system: the host copy (its diagonal
// follows nu dt / h^2) and its boundary terms; the components are solved
// together (GpuFluid::viscousA_, one block system).
template <int D>
struct GpuFluid<D>::Viscous {
  ViscousSystem<D> host;
  GpuBuffer boundaryRhs;
};

namespace {
// The pressure's phi: double in either precision. Its float rounding alone
// leaves a relative residual of eps_float times the system's condition
// (4.5e-4 in the 220 x 41 channel), while the solve's other vectors in float
// still reach 1e-6 (docs/gpu.md, "Precision").
constexpr GpuPrecision kPhi = GpuPrecision::Double;
std::string dimDefine(int D, FluidOp mode) { return fmt::format("#define DIM {}\n#define {}", D, define(mode)); }
}  // namespace

template <int D>
std::array<int, 3> GpuFluid<D>::velocityOffsets() const {
  return {int(off_[0]), int(off_[1]), int(off_[2])};
}

template <int D>
size_t GpuFluid<D>::faces(int a) const {
  size_t n = 1;
  for (int b = 0; b < D; ++b) n *= size_t(cells_[size_t(b)] + (a == b ? 1 : 0));
  return n;
}

template <int D>
GpuFluid<D>::GpuFluid(const FluidSettings& s, const VelocityConstraints<D>& vc, GpuPrecision real)
    : settings_(s), real_(real), h_(vc.h) {
  for (double* tol : {&settings_.pressureTolerance, &settings_.viscosityTolerance})
    *tol = std::max(*tol, toleranceFloor(real));
  cellCount_ = 1;
  for (int a = 0; a < D; ++a) {
    cells_[size_t(a)] = vc.cells[a];
    periodic_[size_t(a)] = vc.boundaries.periodic(a) ? 1 : 0;
    cellCount_ *= size_t(vc.cells[a]);
  }
  std::vector<uint32_t> fixed;
  std::vector<float> value, open;
  for (int a = 0; a < D; ++a) {
    off_[size_t(a)] = faceCount_;
    faceCount_ += faces(a);
    maxGrid_ = std::max(maxGrid_, faces(a));
    fixed.insert(fixed.end(), vc.fixed[a].values().begin(), vc.fixed[a].values().end());
    const std::vector<float> v = vc.prescribedGrid(a), o = vc.open[a].expanded();
    value.insert(value.end(), v.begin(), v.end());
    open.insert(open.end(), o.begin(), o.end());
  }
  open_ = vc.cut.empty() ? GpuBuffer(sizeof(float)) : GpuBuffer::of(open);  // (read for cut obstacles only)
  vel_ = GpuBuffer(faceCount_ * sizeof(float));
  velScratch_ = GpuBuffer(faceCount_ * sizeof(float));
  vel_.zero();
  velScratch_.zero();
  fixed_ = GpuBuffer::of(fixed);
  value_ = GpuBuffer::of(value);
  dye_ = GpuBuffer(cellCount_ * sizeof(float));
  dyeScratch_ = GpuBuffer(cellCount_ * sizeof(float));
  dye_.zero();
  solid_ = GpuBuffer::of(std::vector<uint32_t>(vc.solid.values().begin(), vc.solid.values().end()));
  for (GpuBuffer* b : {&lo_, &hi_, &back_, &fwd_}) *b = GpuBuffer(maxGrid_ * sizeof(float));
  // The pressure: the CPU's system and multigrid levels, uploaded once.
  const LaplaceSystem<D> P = pressureSystem<D>(vc);
  const std::vector<float> diag = P.diag.expanded();
  std::vector<uint32_t> inactive(diag.size());
  for (size_t i = 0; i < diag.size(); ++i) inactive[i] = diag[i] == 0.0f ? 1u : 0u;
  inactive_ = GpuBuffer::of(inactive);
  pressure_ = std::make_unique<GpuLaplace>(P);
  pressure_->setPrecision(real_, kPhi);
  multigrid_ = std::make_unique<GpuMultigrid>(Multigrid<D>(P), *pressure_, MultigridOptions{});
  rhs_ = realBuffer(cellCount_, real_);
  ratePrev_ = realBuffer(cellCount_, GpuPrecision::Float);  // (float, as the CPU keeps it)
  phi_ = realBuffer(cellCount_, kPhi);
  std::vector<const LaplaceSystem<D>*> blocks;
  for (int a = 0; a < D; ++a) {
    auto v = std::make_unique<Viscous>();
    v->host = viscousSystem<D>(vc, a);
    v->host.setRate(1.0);
    const std::vector<float> rhs = v->host.boundaryRhs.expanded();  // (the shader reads reals)
    v->boundaryRhs = realBuffer(rhs.size(), real_);
    uploadReals(&v->boundaryRhs, std::vector<double>(rhs.begin(), rhs.end()), real_);
    blocks.push_back(&v->host.A);
    viscous_[size_t(a)] = std::move(v);
  }
  viscousA_ = std::make_unique<GpuLaplace>(blocks);
  viscousA_->setPrecision(real_);
  // the pressure's and the viscosity's solves (never at once) share their work vectors
  auto work = std::make_shared<GpuPcgWork>(std::max(cellCount_, viscousA_->size()), real_);
  pressurePcg_ = std::make_unique<GpuPcg>(*pressure_, work);
  viscousPcg_ = std::make_unique<GpuPcg>(*viscousA_, work);
  viscousB_ = realBuffer(viscousA_->size(), real_);
  viscousX_ = realBuffer(viscousA_->size(), real_);
  if (!vc.cut.empty()) {  // the viscosity holds the faces inside cut obstacles too
    std::vector<uint32_t> held(fixed);
    for (int a = 0; a < D; ++a) {
      const ViscousSystem<D>& V = viscous_[size_t(a)]->host;
      for (size_t i = 0; i < V.insideCut.size(); ++i)
        if (V.insideCut[i]) held[off_[size_t(a)] + vc.fixed[a].index(latticeCoord<D>(V.dims, i))] = 1u;
    }
    viscousHeld_ = GpuBuffer::of(held);
  }
  dyeActive_ = s.inflowDyeStripes > 0 || s.smoke.enabled;
  if (s.smoke.enabled) {
    solidHost_ = vc.solid;
    temp_ = GpuBuffer::of(std::vector<float>(cellCount_, float(s.smoke.ambient)));
    tempScratch_ = GpuBuffer(cellCount_ * sizeof(float));
    force_ = GpuBuffer(D * cellCount_ * sizeof(float));
    centre_ = GpuBuffer(D * cellCount_ * sizeof(float));
    omega_ = GpuBuffer((D == 2 ? 2 : 4) * cellCount_ * sizeof(float));
    for (const Grid<float, D>& c : sourceCoverage<D>(s.smoke.sources, vc.cells, vc.h, vc.solid))
      cover_.push_back(GpuBuffer::of(c.values()));
  }
  speed_ = std::make_unique<GpuReduction>();
  timer_ = std::make_unique<GpuStageTimer>(FluidStepStats::kStages);
}

template <int D>
size_t GpuFluid<D>::deviceBytes(const IVec<D>& cells, GpuPrecision real) {
  size_t c = 1, f = 0, g = 0;
  for (int a = 0; a < D; ++a) c *= size_t(cells[a]);
  for (int a = 0; a < D; ++a) {
    const size_t fa = c / size_t(cells[a]) * size_t(cells[a] + 1);
    f += fa;
    g = std::max(g, fa);
  }
  const double system = (D + 1) * 4.0;       // face weights and diagonal, float
  const double coarse = 1.0 / ((1 << D) - 1);  // the multigrid levels below the fine one, relative to it
  const double r = double(realBytes(real)), phi = double(realBytes(kPhi));
  const double bytes =
      4.0 * 6 *
          double(f)  // u, its scratch, fixed flags, prescribed values; a cut obstacle's open fractions, held flags
      + 4.0 * 4 * double(c) +
      4.0 * 4 * double(g)  // dye, its scratch, solid, inactive; the schemes' scratch
      // pressure: system, phi, rhs, rate (float); each level's x and b
      + double(c) * (system + phi + r + 4 + 2 * 4 + coarse * (system + 2 * 4)) +
      double(f) * (system + 3 * r + 5 * r);  // viscosity: system, b, x, rhs; the PCG vectors (the pressure's too)
  return size_t(bytes);
}

template <int D>
size_t GpuFluid<D>::deviceBytes() const {
  IVec<D> cells;
  for (int a = 0; a < D; ++a) cells[a] = cells_[size_t(a)];
  return deviceBytes(cells, real_);
}

template <int D>
double GpuFluid<D>::cflTimeStep(double cfl, double dtMax) const {
  const double umax = maxSpeed();
  return umax > 0 ? std::min(dtMax, cfl * h_ / umax) : dtMax;
}

template <int D>
double GpuFluid<D>::maxSpeed() const {
  if (speed_cached_ < 0.0) {
    speed_->maxAbs(vel_, faceCount_, 0);
    speed_cached_ = std::sqrt(double(D)) * speed_->read()[0];
  }
  return speed_cached_;
}

template <int D>
void GpuFluid<D>::readSolverStats() const {
  stats_.pressure = pressurePcg_->tally();
  stats_.viscosity = viscousPcg_->tally();
}

template <int D>
GpuFluid<D>::~GpuFluid() = default;

template <int D>
void GpuFluid<D>::applyConstraints(const GpuBuffer& vel) {
  for (FluidOp mode : {FluidOp::Fixed, FluidOp::Periodic})
    for (int a = 0; a < D; ++a) {
      if (mode == FluidOp::Periodic && !periodic_[size_t(a)]) continue;
      const ComputeProgram& p = useProgram(shader(mode), dimDefine(D, mode), real_, kPhi);
      setUniform(p, "cells", cells_);
      setUniform(p, "axis", a);
      setUniform(p, "n", int(faces(a)));
      setUniform(p, "velOff", velocityOffsets());
      vel.bind(0);
      fixed_.bind(1);
      value_.bind(2);
      dispatchFlat(faces(a), mode == FluidOp::Fixed ? 12.0 : 0.0);  // flag, value, u; (the periodic layer: none)
      storageBarrier();
    }
}

template <int D>
void GpuFluid<D>::forces(double dt) {
  for (int a = 0; a < D; ++a) {
    const float f = float(dt * settings_.force[size_t(a)]);
    const float b = dyeActive_ ? float(dt * settings_.buoyancy * settings_.buoyancyDirection[size_t(a)]) : 0.0f;
    if (f == 0.0f && b == 0.0f) continue;
    const ComputeProgram& p = useProgram(shader(FluidOp::Forces), dimDefine(D, FluidOp::Forces), real_, kPhi);
    setUniform(p, "cells", cells_);
    setUniform(p, "axis", a);
    setUniform(p, "n", int(faces(a)));
    setUniform(p, "velOff", velocityOffsets());
    setUniform(p, "fa", f);
    setUniform(p, "fb", b);
    vel_.bind(0);
    dye_.bind(3);
    dispatchFlat(faces(a), b != 0.0f ? 16.0 : 8.0);
    storageBarrier();
  }
}

template <int D>
void GpuFluid<D>::runSmoke(SmokeOp mode, size_t n, int axis,
                           const std::function<void(const ComputeProgram&)>& uniforms) {
  const ComputeProgram& p = useProgram("smoke.comp", fmt::format("#define DIM {}\n#define {}", D, define(mode)), real_);
  setUniform(p, "cells", cells_);
  setUniform(p, "periodic", periodic_);
  setUniform(p, "velOff", velocityOffsets());
  setUniform(p, "axis", axis);
  setUniform(p, "n", int(n));
  uniforms(p);
  vel_.bind(0);
  dye_.bind(1);
  temp_.bind(2);
  force_.bind(4);
  centre_.bind(5);
  omega_.bind(6);
  dispatchFlat(n, 16.0);
  storageBarrier();
}

// Each source over the part of the step inside its window, where it is at
// mid-step (a moving one's cover computed on the host and uploaded).
template <int D>
void GpuFluid<D>::emitSmoke(double dt) {
  const SmokeSettings& sm = settings_.smoke;
  for (size_t q = 0; q < sm.sources.size(); ++q) {
    const SmokeSource& src = sm.sources[q];
    const double on = std::min(time_ + dt, src.end) - std::max(time_, src.start);
    if (!(on > 0.0)) continue;
    if (!src.motion.empty()) {
      IVec<D> cells;
      for (int a = 0; a < D; ++a) cells[a] = cells_[size_t(a)];
      cover_[q].upload(sourceCover<D>(src, time_ + 0.5 * dt, cells, h_, solidHost_).values());
    }
    cover_[q].bind(3);
    runSmoke(SmokeOp::Emit, cellCount_, 0, [&](const ComputeProgram& p) {
      setUniform(p, "dRho", src.density * on);
      setUniform(p, "dT", src.temperature * on);
    });
    if (!src.inject) continue;
    for (int a = 0; a < D; ++a)
      runSmoke(SmokeOp::Inject, faces(a), a,
               [&](const ComputeProgram& p) { setUniform(p, "value", src.velocity[size_t(a)]); });
  }
}

// Buoyancy and confinement as cell-centred forces, then onto the faces.
template <int D>
void GpuFluid<D>::smokeForces(double dt) {
  const SmokeSettings& sm = settings_.smoke;
  const bool buoyant = sm.weight != 0.0 || sm.heat != 0.0;
  if (!buoyant && sm.vorticity == 0.0) return;
  force_.zero();
  if (buoyant)
    runSmoke(SmokeOp::Buoyancy, cellCount_, 0, [&](const ComputeProgram& p) {
      setUniform(p, "alpha", sm.weight);
      setUniform(p, "beta", sm.heat);
      setUniform(p, "ambient", sm.ambient);
      setUniformDoubles(p, "up", settings_.buoyancyDirection.data(), 1, 3);
    });
  if (sm.vorticity != 0.0) {
    auto hs = [&](const ComputeProgram& p) {
      setUniform(p, "h", h_);
      setUniform(p, "s", sm.vorticity * h_);
    };
    runSmoke(SmokeOp::Centre, cellCount_, 0, hs);
    runSmoke(SmokeOp::Vorticity, cellCount_, 0, hs);
    runSmoke(SmokeOp::Confine, cellCount_, 0, hs);
  }
  for (int a = 0; a < D; ++a)
    runSmoke(SmokeOp::AddFaces, faces(a), a, [&](const ComputeProgram& p) { setUniform(p, "dt", dt); });
}

template <int D>
void GpuFluid<D>::decaySmoke(double dt) {
  const SmokeSettings& sm = settings_.smoke;
  if (sm.dissipation <= 0.0 && sm.cooling <= 0.0) return;
  runSmoke(SmokeOp::Decay, cellCount_, 0, [&](const ComputeProgram& p) {
    setUniform(p, "keepRho", sm.dissipation > 0.0 ? std::exp(-sm.dissipation * dt) : 1.0);
    setUniform(p, "keepT", sm.cooling > 0.0 ? std::exp(-sm.cooling * dt) : 1.0);
    setUniform(p, "ambient", sm.ambient);
  });
}

// One grid through the scheme: src (at srcOff) -> dst (at dstOff), as advectField in fluid/advection.cpp.
template <int D>
void GpuFluid<D>::advectField(const GpuBuffer& src, size_t srcOff, const std::array<int, 3>& dims,
                              const std::array<float, 3>& offset, double dt, GpuBuffer* dst, size_t dstOff) {
  const size_t n = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
  auto pass = [&](const GpuBuffer& in, size_t inOff, double step, GpuBuffer* out, size_t outOff, bool limits) {
    const ComputeProgram& p =
        useProgram("advect.comp", fmt::format("#define DIM {}{}", D, limits ? "\n#define LIMITS" : ""));
    setUniform(p, "cells", cells_);
    setUniform(p, "periodic", periodic_);
    setUniform(p, "velOff", velocityOffsets());
    setUniform(p, "c", float(step / h_));
    setUniform(p, "sdims", dims);
    setUniform(p, "soff", offset);
    setUniform(p, "srcOff", int(inOff));
    setUniform(p, "dstOff", int(outOff));
    vel_.bind(0);
    in.bind(1);
    out->bind(2);
    lo_.bind(3);
    hi_.bind(4);
    dispatchFlat(n, 8.0 + 4.0 * D + (limits ? 8.0 : 0.0));  // src, dst, the velocity once (, lo, hi)
    storageBarrier();
  };
  auto combine = [&](FluidOp mode, const GpuBuffer& f0, size_t f0Off, const GpuBuffer& f1, size_t f1Off,
                     const GpuBuffer& f2, const GpuBuffer& f3, const GpuBuffer& f4) {
    const ComputeProgram& p = useProgram(shader(mode), dimDefine(D, mode), real_, kPhi);
    setUniform(p, "n", int(n));
    setUniform(p, "dstOff", int(f0Off));
    setUniform(p, "f1Off", int(f1Off));
    f0.bind(3);
    f1.bind(4);
    f2.bind(5);
    f3.bind(6);
    f4.bind(11);
    dispatchFlat(n, mode == FluidOp::MacCormack ? 24.0 : mode == FluidOp::BfeccCorrect ? 12.0 : 16.0);
    storageBarrier();
  };
  switch (settings_.advection) {
    case AdvectionScheme::SemiLagrangian:
      pass(src, srcOff, dt, dst, dstOff, false);
      break;
    case AdvectionScheme::MacCormack:
      // phi^ = A(phi); phi~ = A^-1(phi^); phi = phi^ + (phi - phi~) / 2, limited
      pass(src, srcOff, dt, dst, dstOff, true);
      pass(*dst, dstOff, -dt, &back_, 0, false);
      combine(FluidOp::MacCormack, *dst, dstOff, src, srcOff, back_, lo_, hi_);
      break;
    case AdvectionScheme::Bfecc:
      // phi_bar = phi + (phi - A^-1 A phi) / 2, then A(phi_bar), limited
      pass(src, srcOff, dt, &fwd_, 0, false);
      pass(fwd_, 0, -dt, &back_, 0, false);
      combine(FluidOp::BfeccCorrect, fwd_, 0, src, srcOff, back_, back_, back_);
      pass(fwd_, 0, dt, dst, dstOff, false);
      pass(src, srcOff, dt, &back_, 0, true);  // the first-order fallback
      combine(FluidOp::BfeccLimit, *dst, dstOff, back_, 0, lo_, hi_, hi_);
      break;
  }
}

template <int D>
void GpuFluid<D>::advect(double dt) {
  for (int a = 0; a < D; ++a) {
    std::array<int, 3> dims = cells_;
    dims[size_t(a)] += 1;
    std::array<float, 3> offset{0.5f, 0.5f, 0.5f};
    offset[size_t(a)] = 0.0f;
    if (D == 2) offset[2] = 0.0f;
    advectField(vel_, off_[size_t(a)], dims, offset, dt, &velScratch_, off_[size_t(a)]);
  }
  // The dye through the same field (a dye that is all zero advects to zero).
  if (dyeActive_) {
    advectField(dye_, 0, cells_, {0.5f, 0.5f, D == 3 ? 0.5f : 0.0f}, dt, &dyeScratch_, 0);
    std::swap(dye_, dyeScratch_);
  }
  if (settings_.smoke.enabled) {
    advectField(temp_, 0, cells_, {0.5f, 0.5f, D == 3 ? 0.5f : 0.0f}, dt, &tempScratch_, 0);
    std::swap(temp_, tempScratch_);
  }
  std::swap(vel_, velScratch_);
}

template <int D>
void GpuFluid<D>::injectInflowDye() {
  for (int a = 0; a < D; ++a)
    for (bool high : {false, true}) {
      if (settings_.inflowDyeStripes <= 0 || settings_.boundaries.side(a, high).kind != BoundaryKind::Inflow) continue;
      const ComputeProgram& p = useProgram(shader(FluidOp::InflowDye), dimDefine(D, FluidOp::InflowDye), real_, kPhi);
      setUniform(p, "cells", cells_);
      setUniform(p, "n", int(cellCount_));
      setUniform(p, "inflow", std::array<int, 4>{a, high ? 1 : 0, a == 0 ? 1 : 0, settings_.inflowDyeStripes});
      dye_.bind(3);
      solid_.bind(10);
      dispatchFlat(cellCount_, 0.0);  // one layer of cells
      storageBarrier();
    }
}

template <int D>
void GpuFluid<D>::diffuse(double dt) {
  stats_.viscosity = SolverResult{};
  stats_.viscosity.converged = true;
  const double nu = settings_.viscosity;
  if (nu <= 0 || dt <= 0) return;
  const double s = nu * dt / (h_ * h_);
  auto run = [&](FluidOp mode, int a) {
    const Viscous& V = *viscous_[size_t(a)];
    std::array<int, 3> udims{1, 1, 1};
    for (int b = 0; b < D; ++b) udims[size_t(b)] = V.host.dims[b];
    const ComputeProgram& p = useProgram(shader(mode), dimDefine(D, mode), real_, kPhi);
    setUniform(p, "cells", cells_);
    setUniform(p, "axis", a);
    setUniform(p, "n", int(V.host.A.size()));
    setUniform(p, "udims", udims);
    setUniform(p, "velOff", velocityOffsets());
    setUniform(p, "s", s);
    setUniform(p, "blockOff", int(viscousA_->blockStart(a)));
    vel_.bind(0);
    (viscousHeld_.bytes() ? viscousHeld_ : fixed_).bind(1);
    viscousB_.bind(7);
    viscousX_.bind(8);
    V.boundaryRhs.bind(9);
    dispatchFlat(V.host.A.size(), mode == FluidOp::ViscousSetup ? 32.0 : 16.0);
  };
  for (int a = 0; a < D; ++a) {
    if (s != s_) {
      viscous_[size_t(a)]->host.setRate(s);
      viscousA_->updateBlock(a, viscous_[size_t(a)]->host.A);
    }
    run(FluidOp::ViscousSetup, a);
  }
  storageBarrier();
  // The components as one block system, to the relative residual of the
  // whole velocity system (the CPU's: sum_a ||r_a||^2 <= tol^2 sum_a
  // ||b_a||^2); its result read with the pressure's (readSolverStats).
  foldWorst(&stats_.viscosity,
            viscousPcg_->solve(&viscousB_, &viscousX_, nullptr, {settings_.viscosityTolerance, 500}, true));
  for (int a = 0; a < D; ++a) run(FluidOp::ViscousStore, a);
  storageBarrier();
  s_ = s;
  applyConstraints(vel_);
}

template <int D>
void GpuFluid<D>::project(double dt) {
  auto run = [&](FluidOp mode, int axis, size_t n) {
    const bool cut = mode == FluidOp::Divergence && viscousHeld_.bytes() > 0;  // (made for cut obstacles only)
    const ComputeProgram& p =
        useProgram(shader(mode), dimDefine(D, mode) + (cut ? "\n#define CUT_FACES" : ""), real_, kPhi);
    setUniform(p, "cells", cells_);
    setUniform(p, "periodic", periodic_);
    setUniform(p, "axis", axis);
    setUniform(p, "n", int(n));
    setUniform(p, "velOff", velocityOffsets());
    setUniform(p, "invH", 1.0 / h_);
    setUniform(p, "dt", dt);
    setUniform(p, "invLastDt", lastDt_ > 0 ? 1.0 / lastDt_ : 0.0);
    setUniform(p, "extrapolate", solves_ >= 2 ? 1 : 0);
    vel_.bind(0);
    fixed_.bind(1);
    (mode == FluidOp::Divergence ? rhs_ : phi_).bind(7);
    ratePrev_.bind(8);
    inactive_.bind(10);
    open_.bind(12);
    dispatchFlat(n, mode == FluidOp::Divergence ? 12.0 * D + 12.0 : 32.0);
    storageBarrier();
  };
  run(FluidOp::Divergence, 0, cellCount_);
  // Warm start: phi / dt extrapolated from the last two projections.
  if (solves_ >= 1 && lastDt_ > 0) run(FluidOp::WarmStart, 0, cellCount_);
  stats_.pressure = pressurePcg_->solve(&rhs_, &phi_, multigrid_.get(),
                                        {settings_.pressureTolerance, settings_.pressureMaxIterations}, true);
  lastDt_ = dt;
  solves_ = dt > 0 ? std::min(solves_ + 1, 2) : 0;
  for (int a = 0; a < D; ++a) run(FluidOp::Gradient, a, faces(a));
  applyConstraints(vel_);
  if (statsDue(steps_ + 1)) readSolverStats();  // (steps_ counts this step at its end)
}

// The GPU's stages of the fluid step, whose order is fluid/fluid_step.h's.
template <int D>
struct GpuFluid<D>::Stages {
  GpuFluid& f;
  void mark(int stage) {
    f.timer_->mark(stage);
    if (stage < FluidStepStats::kStages) return;
    const std::vector<double> seconds = f.timer_->endStep();
    for (int k = 0; k < FluidStepStats::kStages; ++k) f.stats_.seconds[size_t(k)] = seconds[size_t(k)];
  }
  bool smoke() const { return f.settings_.smoke.enabled; }
  void emitSmoke(double dt) { f.emitSmoke(dt); }
  void forces(double dt) { f.forces(dt); }
  void smokeForces(double dt) { f.smokeForces(dt); }
  void constrain() { f.applyConstraints(f.vel_); }
  void advect(double dt) { f.advect(dt); }
  void injectInflowDye() { f.injectInflowDye(); }
  void decaySmoke(double dt) { f.decaySmoke(dt); }
  void diffuse(double dt) { f.diffuse(dt); }
  void project(double dt) { f.project(dt); }
  void advanceClock(double dt) {
    f.time_ += dt;
    ++f.steps_;
  }
};

template <int D>
void GpuFluid<D>::step(double dt) {
  counts_.add([&] {
    Stages stages{*this};
    stepFluid(stages, dt);
    speed_cached_ = -1.0;
  });
  ++counts_.steps;
}

template <int D>
void GpuFluid<D>::toHost(FluidSolver<D>* host) const {
  readSolverStats();
  download(&host->velocity(), &host->dye(), host->temperature().empty() ? nullptr : &host->temperature());
  host->adopt(time_, steps_, phi(), lastDt_);
}

template <int D>
void GpuFluid<D>::fromHost(const FluidSolver<D>& host) {
  upload(host.velocity(), host.dye(), host.temperature().empty() ? nullptr : &host.temperature());
  time_ = host.time();
  steps_ = host.steps();
}

template <int D>
void GpuFluid<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
  (*run)["pressure_solver"] = "mgpcg";
  nlohmann::json g = counts_.perStep();
  g["stages"] = timer_->countsPerStep(FluidStepStats::kStageNames);
  g["precision"] = precisionName(real_);
  g["tolerances"] = tolerances();
  g["device_bytes"] = {{"fluid", deviceBytes()}, {"allocated_peak", GpuBuffer::peakBytes()}};
  (*run)["gpu"] = g;
}

template <int D>
void GpuFluid<D>::upload(const MacVelocity<D>& u, const Grid<float, D>& dye, const Grid<float, D>* temperature) {
  speed_cached_ = -1.0;
  for (int a = 0; a < D; ++a) vel_.upload(u[a].values(), off_[size_t(a)] * sizeof(float));
  dye_.upload(dye.values());
  if (temperature && settings_.smoke.enabled) temp_.upload(temperature->values());
  dyeActive_ = settings_.inflowDyeStripes > 0 || settings_.smoke.enabled ||
               std::any_of(dye.values().begin(), dye.values().end(), [](float v) { return v != 0.0f; });
}

template <int D>
void GpuFluid<D>::download(MacVelocity<D>* u, Grid<float, D>* dye, Grid<float, D>* temperature) const {
  for (int a = 0; a < D; ++a) vel_.download((*u)[a].data(), faces(a) * sizeof(float), off_[size_t(a)] * sizeof(float));
  if (dye) dye_.download(dye->data(), cellCount_ * sizeof(float));
  if (temperature && settings_.smoke.enabled) temp_.download(temperature->data(), cellCount_ * sizeof(float));
}

template <int D>
std::vector<double> GpuFluid<D>::phi() const {
  return readReals(phi_, cellCount_, kPhi);
}

template <int D>
void GpuFluid<D>::save(StateWriter* out) const {
  out->putVector("gpu.fluid.phi", readReals(phi_, cellCount_, kPhi));
  out->putVector("gpu.fluid.rate_prev", readReals(ratePrev_, cellCount_, GpuPrecision::Float));
  out->put("gpu.fluid.last_dt", lastDt_);
  out->put("gpu.fluid.solves", solves_);
}

template <int D>
void GpuFluid<D>::load(const StateReader& in) {
  std::vector<double> v(cellCount_);
  in.getVector("gpu.fluid.phi", &v);
  uploadReals(&phi_, v, kPhi);
  in.getVector("gpu.fluid.rate_prev", &v);
  uploadReals(&ratePrev_, v, GpuPrecision::Float);
  in.get("gpu.fluid.last_dt", &lastDt_);
  in.get("gpu.fluid.solves", &solves_);
}

template class GpuFluid<2>;
template class GpuFluid<3>;

}  // namespace morphoflow
