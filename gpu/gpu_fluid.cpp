#include "gpu/gpu_fluid.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fluid/fluid_step.h"
#include "fluid/obstacle_motion.h"
#include "gpu/compute_program.h"
#include "gpu/fluid/gpu_fill.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_gate.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"
#include "gpu/gpu_reduction.h"
#include "gpu/gpu_stage_timer.h"

namespace morphoflow {

namespace {
FluidSettings withFloors(FluidSettings s, GpuPrecision real) {
  for (double* tol : {&s.pressureTolerance, &s.viscosityTolerance}) *tol = std::max(*tol, toleranceFloor(real));
  return s;
}
}  // namespace

template <int D>
GpuFluid<D>::GpuFluid(const FluidSettings& s, const VelocityConstraints<D>& vc, GpuPrecision real)
    : settings_(withFloors(s, real)),
      real_(real),
      placement_(s, vc.cells, vc.h),
      vc_(placement_.moves() ? placement_.constraintsAt(0.0) : VelocityConstraints<D>()),
      grid_(constraints(vc)),
      advection_(grid_, s.advection, real),
      viscosity_(constraints(vc), &grid_, real),
      projection_(constraints(vc), &grid_, real, viscosity_.work()) {  // (their solves share the work vectors)
  dye_ = GpuBuffer(grid_.cellCount * sizeof(float));
  dyeScratch_ = GpuBuffer(grid_.cellCount * sizeof(float));
  dye_.zero();
  dyeActive_ = s.inflowDyeStripes > 0 || s.smoke.enabled;
  if (s.smoke.enabled) smoke_ = std::make_unique<GpuSmoke<D>>(settings_, constraints(vc), &grid_, real);
  speed_ = std::make_unique<GpuReduction>();
  timer_ = std::make_unique<GpuStageTimer>(FluidStepStats::kStages);
  if (placement_.moves()) {
    obstacles_ = std::make_unique<GpuObstacles<D>>(settings_, &grid_);
    obstacles_->place(placement_.placed(), placement_.motions(), IVec<D>(0), vc_.cells);
  }
}

template <int D>
GpuFluid<D>::~GpuFluid() = default;

template <int D>
size_t GpuFluid<D>::deviceBytes(const IVec<D>& cells, GpuPrecision real) {
  size_t c = 1, f = 0, g = 0;
  for (int a = 0; a < D; ++a) c *= size_t(cells[a]);
  for (int a = 0; a < D; ++a) {
    const size_t fa = c / size_t(cells[a]) * size_t(cells[a] + 1);
    f += fa;
    g = std::max(g, fa);
  }
  const double system = (D + 2) * 4.0;         // face weights, c and diagonal, float
  const double coarse = 1.0 / ((1 << D) - 1);  // the multigrid levels below the fine one, relative to it
  const double r = double(realBytes(real)), phi = double(realBytes(kPhiPrecision));
  const double bytes =
      // u, its scratch, fixed flags, prescribed values; a cut obstacle's open fractions, held flags
      4.0 * 6 * double(f) + 4.0 * 4 * double(c) +
      4.0 * 4 * double(g)  // dye, its scratch, solid, inactive; the schemes' scratch
      // pressure: system, phi, rhs, rate (float); each level's x and b
      + double(c) * (system + phi + r + 4 + 2 * 4 + coarse * (system + 2 * 4)) +
      double(f) * (system + 3 * r + 5 * r);  // viscosity: system, b, x, rhs; the PCG vectors (the pressure's too)
  return size_t(bytes);
}

template <int D>
size_t GpuFluid<D>::deviceBytes() const {
  IVec<D> cells;
  for (int a = 0; a < D; ++a) cells[a] = grid_.cells[size_t(a)];
  return deviceBytes(cells, real_);
}

template <int D>
double GpuFluid<D>::cflTimeStep(double cfl, double dtMax) const {
  double umax = maxSpeed();
  for (const ObstacleSpec& o : settings_.obstacles) umax = std::max(umax, obstacleSpeedBound(o, D, time_));
  return umax > 0 ? std::min(dtMax, cfl * grid_.h / umax) : dtMax;
}

template <int D>
double GpuFluid<D>::maxSpeed() const {
  if (speed_cached_ < 0.0) {
    speed_->maxAbs(grid_.vel, grid_.faceCount, 0);
    speed_cached_ = std::sqrt(double(D)) * speed_->read()[0];
  }
  return speed_cached_;
}

template <int D>
void GpuFluid<D>::readSolverStats() const {
  stats_.pressure = projection_.tally();
  stats_.viscosity = viscosity_.tally();
}

template <int D>
void GpuFluid<D>::forces(double dt) {
  for (int a = 0; a < D; ++a) {
    const float f = float(dt * settings_.force[size_t(a)]);
    const float b = dyeActive_ ? float(dt * settings_.buoyancy * settings_.buoyancyDirection[size_t(a)]) : 0.0f;
    if (f == 0.0f && b == 0.0f) continue;
    const ComputeProgram& p = grid_.stage(FluidOp::Forces, real_);
    setUniform(p, "cells", grid_.cells);
    setUniform(p, "axis", a);
    setUniform(p, "n", int(grid_.faces(a)));
    setUniform(p, "velOff", grid_.velocityOffsets());
    setUniform(p, "fa", f);
    setUniform(p, "fb", b);
    grid_.vel.bind(0);
    dye_.bind(3);
    dispatchFlat(grid_.faces(a), b != 0.0f ? 16.0 : 8.0);
    storageBarrier();
  }
}

// The velocity through itself into its scratch (kept for the chemicals:
// advectedVelocity), the dye and the temperature through it.
template <int D>
void GpuFluid<D>::advect(double dt) {
  for (int a = 0; a < D; ++a) {
    std::array<int, 3> dims = grid_.cells;
    dims[size_t(a)] += 1;
    std::array<float, 3> offset{0.5f, 0.5f, 0.5f};
    offset[size_t(a)] = 0.0f;
    if (D == 2) offset[2] = 0.0f;
    advection_.advect(grid_.vel, grid_.off[size_t(a)], dims, offset, dt, &grid_.velScratch, grid_.off[size_t(a)]);
  }
  const std::array<float, 3> centres{0.5f, 0.5f, D == 3 ? 0.5f : 0.0f};
  // The dye through the same field (a dye that is all zero advects to zero).
  if (dyeActive_) {
    advection_.advect(dye_, 0, grid_.cells, centres, dt, &dyeScratch_, 0);
    std::swap(dye_, dyeScratch_);
  }
  if (smoke_) {
    advection_.advect(smoke_->temperature(), 0, grid_.cells, centres, dt, &smoke_->temperatureScratch(), 0);
    std::swap(smoke_->temperature(), smoke_->temperatureScratch());
  }
  std::swap(grid_.vel, grid_.velScratch);
}

template <int D>
void GpuFluid<D>::injectInflowDye() {
  for (int a = 0; a < D; ++a)
    for (bool high : {false, true}) {
      if (settings_.inflowDyeStripes <= 0 || settings_.boundaries.side(a, high).kind != BoundaryKind::Inflow) continue;
      const ComputeProgram& p = grid_.stage(FluidOp::InflowDye, real_);
      setUniform(p, "cells", grid_.cells);
      setUniform(p, "n", int(grid_.cellCount));
      setUniform(p, "inflow", std::array<int, 4>{a, high ? 1 : 0, a == 0 ? 1 : 0, settings_.inflowDyeStripes});
      dye_.bind(3);
      grid_.solid.bind(10);
      dispatchFlat(grid_.cellCount, 0.0);  // one layer of cells
      storageBarrier();
    }
}

// Moving obstacles, as FluidSolver::placeObstacles: the constraints, the
// pressure and viscous systems at time t, and with `fill` the cells and
// faces the solid uncovers filled from their fluid neighbours (the host's
// plan, gpu/fluid/gpu_fill.h).
template <int D>
void GpuFluid<D>::placeObstacles(double t, bool fill) {
  if (!placement_.moves()) return;
  IVec<D> lo, hi;
  if (!placement_.moveTo(t, &vc_, &lo, &hi)) return;
  obstacles_->place(placement_.placed(), placement_.motions(), lo, hi);
  projection_.rebuild(vc_, lo, hi);
  if (settings_.viscosity > 0) viscosity_.rebuild(vc_, lo, hi);  // (an inviscid fluid never solves it)
  if (smoke_) smoke_->setSolid(vc_.solid);
  if (!fill) return;
  const GpuFill cells(placement_.cellFill(vc_));
  cells.apply(dye_, 0, GpuPrecision::Float);
  if (smoke_) cells.apply(smoke_->temperature(), 0, GpuPrecision::Float);
  for (int a = 0; a < D; ++a)
    GpuFill(placement_.faceFill(vc_, a)).apply(grid_.vel, grid_.off[size_t(a)], GpuPrecision::Float);
  grid_.constrain(grid_.vel, real_);
  speed_cached_ = -1.0;
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
  void resumeClock() {}  // (the device's step is given no caller's work)
  void releaseAdvected() {}  // (the device keeps its velScratch)
  bool smoke() const { return bool(f.smoke_); }
  void emitSmoke(double dt) { f.smoke_->emit(f.time_, dt, &f.dye_); }
  void forces(double dt) { f.forces(dt); }
  void smokeForces(double dt) { f.smoke_->forces(dt, f.dye_); }
  void constrain() { f.grid_.constrain(f.grid_.vel, f.real_); }
  void advect(double dt) { f.advect(dt); }
  void injectInflowDye() { f.injectInflowDye(); }
  void decaySmoke(double dt) { f.smoke_->decay(dt, &f.dye_); }
  void diffuse(double dt) {
    f.stats_.viscosity = SolverResult{};
    f.stats_.viscosity.converged = true;
    const double nu = f.settings_.viscosity;
    if (nu <= 0 || dt <= 0) return;
    // (its result read with the pressure's: readSolverStats)
    foldWorst(&f.stats_.viscosity, f.viscosity_.diffuse(nu, dt, f.settings_.viscosityTolerance));
  }
  void project(double dt) {
    f.stats_.pressure = f.projection_.project(dt, {f.settings_.pressureTolerance, f.settings_.pressureMaxIterations});
    if (statsDue(f.steps_ + 1)) f.readSolverStats();  // (steps_ counts this step at its end)
  }
  void advanceClock(double dt) {
    f.time_ += dt;
    ++f.steps_;
  }
};

template <int D>
void GpuFluid<D>::step(double dt) {
  counts_.add([&] {
    // The solid where the step ends, which the projection meets.
    if (placement_.moves() && placement_.time() != time_ + dt) placeObstacles(time_ + dt, true);
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
  host->adopt(time_, steps_, phi(), lastDt());
}

template <int D>
void GpuFluid<D>::fromHost(const FluidSolver<D>& host) {
  if (placement_.moves() && placement_.time() != host.time()) placeObstacles(host.time(), false);
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
  for (int a = 0; a < D; ++a) grid_.vel.upload(u[a].values(), grid_.off[size_t(a)] * sizeof(float));
  dye_.upload(dye.values());
  if (temperature && smoke_) smoke_->temperature().upload(temperature->values());
  dyeActive_ = settings_.inflowDyeStripes > 0 || settings_.smoke.enabled ||
               std::any_of(dye.values().begin(), dye.values().end(), [](float v) { return v != 0.0f; });
}

template <int D>
void GpuFluid<D>::download(MacVelocity<D>* u, Grid<float, D>* dye, Grid<float, D>* temperature) const {
  for (int a = 0; a < D; ++a)
    grid_.vel.download((*u)[a].data(), grid_.faces(a) * sizeof(float), grid_.off[size_t(a)] * sizeof(float));
  if (dye) dye_.download(dye->data(), grid_.cellCount * sizeof(float));
  if (temperature && smoke_) smoke_->temperature().download(temperature->data(), grid_.cellCount * sizeof(float));
}

template <int D>
std::vector<double> GpuFluid<D>::phi() const {
  return projection_.phi();
}

template <int D>
void GpuFluid<D>::save(StateWriter* out) const {
  projection_.save(out);
}

template <int D>
void GpuFluid<D>::load(const StateReader& in) {
  projection_.load(in);
}

template class GpuFluid<2>;
template class GpuFluid<3>;

}  // namespace morphoflow
