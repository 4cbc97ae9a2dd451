#include "gpu/gpu_rd_layer.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cmath>

#include "core/multigrid.h"
#include "gpu/compute_program.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_models.h"
#include "gpu/gpu_multigrid.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"
#include "rd/cosine_lobe.h"
#include "rd/diffusion_tensor.h"
#include "rd/rd_step.h"

namespace morphoflow {

// One species' implicit system for the current theta dt, its solver, and the
// last step's diffusive change (the warm start).
template <int D>
struct GpuRDLayer<D>::Diffusion {
  double thetaDt = -1.0;
  AnisotropicSystem<D> host;  // the shifted system, I + theta dt d (-lap)
  std::unique_ptr<GpuLaplace> A;
  std::unique_ptr<GpuMultigrid> M;
  std::unique_ptr<GpuPcg> pcg;
  GpuBuffer increment;
  double incrementThetaDt = 0.0;
  bool hasIncrement = false;
};

template <int D>
GpuRDLayer<D>::GpuRDLayer(const LayerUpload<D>& upload, GpuPrecision real)
    : up_(upload), real_(real), species_(upload.species), n_(upload.state[0]->size()) {
  up_.settings.tolerance = std::max(up_.settings.tolerance, toleranceFloor(real));
  const LayerUpload<D>& rd = up_;
  for (size_t k = 0; k < rd.parameters.size() && k < params_.size(); ++k) params_[k] = rd.parameters[k];
  for (int s : rd.clamped) clamped_ |= 1u << s;
  // Kim & Lin's implicit reaction writes no rates; the species' solves, one
  // after another, share a work vector and the PCG's.
  const bool rates = rd.settings.integrator != RDIntegrator::KimLin;
  for (int s = 0; s < species_; ++s) {
    x_[size_t(s)] = realBuffer(*rd.state[size_t(s)], real_);
    rates_[size_t(s)] = realBuffer(rates ? n_ : 1, real_);
    diffusion_[size_t(s)] = std::make_unique<Diffusion>();
    diffusion_[size_t(s)]->increment = realBuffer(n_, real_);
  }
  work_ = realBuffer(n_, real_);
  pcgWork_ = std::make_shared<GpuPcgWork>(n_, real_);
  stats_buffer_ = GpuBuffer(2 * sizeof(uint32_t));
  stats_buffer_.zero();
  // each species' operator (a tensor's for the anisotropic ones), for the
  // explicit part (theta < 1) and the operators rebuilt every step
  for (int s = 0; s < species_; ++s) {
    if (diffusionTheta(rd.settings.integrator) == 1.0 && !rebuilt(s)) continue;
    operator_[size_t(s)] = std::make_unique<GpuLaplace>(*rd.operators[size_t(s)]);
    operator_[size_t(s)]->setPrecision(real_);
  }
  // parameter maps (and perturbations), concatenated
  std::vector<double> maps;
  mapAt_.fill(-1);
  for (size_t k = 0; k < rd.parameters.size() && k < mapAt_.size(); ++k) {
    const std::vector<double>& f = *rd.parameterMaps[k];
    if (f.empty()) continue;
    mapAt_[k] = int(maps.size());
    maps.insert(maps.end(), f.begin(), f.end());
  }
  maps_ = realBuffer(maps.empty() ? std::vector<double>{0.0} : maps, real_);
  for (int s = 0; s < species_; ++s) {
    const size_t si = size_t(s);
    if (rd.fixedMasks[si]) {
      isFixed_[si] = true;
      fixedMask_[si] = GpuBuffer::of(std::vector<uint32_t>(rd.fixedMasks[si]->begin(), rd.fixedMasks[si]->end()));
      fixedValue_[si] = realBuffer(*rd.fixedValues[si], real_);
    }
    if (rd.dirichletFaces[si]) faces_[si] = realBuffer(*rd.dirichletFaces[si], real_);
  }
  for (int s : rd.settings.frozen) isFrozen_[size_t(s)] = true;
  if (const DiffusionTensorSpec<D>* t = rd.tensor; t && t->dynamic()) {
    std::vector<double> dir;
    for (int a = 0; a < D; ++a) dir.insert(dir.end(), t->direction[size_t(a)].begin(), t->direction[size_t(a)].end());
    direction_ = realBuffer(dir, real_);
    lambda1_ = realBuffer(t->lambda1, real_);
    lambda2_ = realBuffer(t->lambda2, real_);
    sigma_ = realBuffer(n_ * AnisotropicSystem<D>::kComponents, real_);
    for (int s = 0; s < species_; ++s)
      if (rd.anisotropic[size_t(s)] && !faces_[size_t(s)].id()) faces_[size_t(s)] = realBuffer(n_, real_);
  }
  if (const CosineLobeSpec* lobes = rd.lobes) {
    lobeA_ = realBuffer(n_, real_);
    std::vector<double> rot(lobes->theta0.empty() ? 2 : 2 * n_);
    for (size_t i = 0; i < lobes->theta0.size(); ++i) {
      rot[2 * i] = std::cos(lobes->theta0[i]);
      rot[2 * i + 1] = std::sin(lobes->theta0[i]);
    }
    rot_ = realBuffer(rot, real_);
    for (int s = 0; s < species_; ++s)
      if (rd.lobed[size_t(s)] && !faces_[size_t(s)].id()) faces_[size_t(s)] = realBuffer(n_, real_);
  }
  allHeld_ = GpuBuffer::of(std::vector<uint32_t>(rd.settings.frozen.empty() ? 1 : n_, 1u));
}

template <int D>
GpuRDLayer<D>::~GpuRDLayer() = default;

template <int D>
size_t GpuRDLayer<D>::deviceBytes(size_t n, int species, GpuPrecision real) {
  // per species: the species, its rates (an upper bound: Kim & Lin has none),
  // the warm start, two systems (D weights, c, diagonal: the explicit
  // operator and the implicit one) and a multigrid's levels; once: the work
  // vector and the PCG's five
  const size_t r = realBytes(real);
  return n * (size_t(species) * (3 * r + 2 * (D + 2) * 4 + 3 * 4 * 2) + 6 * r);
}

template <int D>
void GpuRDLayer<D>::vectorOp(VectorOp op, const GpuBuffer& x, GpuBuffer* y, double a, double b,
                             const GpuBuffer* held) const {
  const ComputeProgram& p = useProgram("vector_ops.comp", std::string("#define ") + define(op), real_);
  setUniform(p, "n", int(n_));
  setUniform(p, "ca", a);
  setUniform(p, "cb", b);
  x.bind(0);
  y->bind(1);
  for (int k = 2; k <= 6; ++k) x.bind(k);
  (held ? *held : x).bind(7);
  dispatchFlat(n_, held ? 20.0 : 24.0);
  storageBarrier();
}

template <int D>
void GpuRDLayer<D>::thetaStep(const GpuBuffer& rates, GpuBuffer* x, const GpuBuffer& ax, const GpuBuffer& faces,
                              double dt, double explicitD, double ghost) const {
  const ComputeProgram& p = useProgram("vector_ops.comp", std::string("#define ") + define(VectorOp::ThetaStep), real_);
  setUniform(p, "n", int(n_));
  setUniform(p, "ca", dt);
  setUniform(p, "cb", explicitD);
  setUniform(p, "cc", ghost);
  rates.bind(0);
  x->bind(1);
  ax.bind(2);
  faces.bind(3);
  for (int k = 4; k <= 7; ++k) rates.bind(k);
  dispatchFlat(n_, 40.0);
  storageBarrier();
}

template <int D>
void GpuRDLayer<D>::react(double dt, bool implicit) {
  // Each parameter by a constant index, so the compiler keeps p[] in registers.
  std::string gather = "#define GATHER_PARAMETERS";
  for (size_t k = 0; k < up_.parameters.size(); ++k)
    gather += fmt::format(" p[{0}] = mapAt[{0}] < 0 ? uniformP[{0}] : maps[mapAt[{0}] + i];", k);
  const ComputeProgram& p = useProgram("rd_react.comp",
                                       gpuReaction(up_.settings.model, real_) + gather + "\n" +
                                           (implicit ? "#define MODE_IMPLICIT" : "#define MODE_RATES"),
                                       real_);
  setUniform(p, "n", int(n_));
  setUniform(p, "dt", dt);
  setUniformDoubles(p, "uniformP", params_.data(), int(params_.size()));
  glUniform1iv(p.uniform("mapAt"), GLsizei(mapAt_.size()), mapAt_.data());
  glUniform1ui(p.uniform("clamped"), clamped_);
  for (int s = 0; s < kMax; ++s) {  // (the unused bindings of a block array need a buffer too)
    x_[size_t(s < species_ ? s : 0)].bind(s);
    rates_[size_t(s < species_ ? s : 0)].bind(6 + s);
  }
  stats_buffer_.bind(12);
  maps_.bind(13);
  dispatchFlat(n_, 2.0 * double(realBytes(real_)) * species_);  // the species read and written (or rates written)
  storageBarrier();
}

// Solves (I - theta dt d lap) x' = x in place for species s.
template <int D>
SolverResult GpuRDLayer<D>::diffuse(int s, double thetaDt) {
  const double d = up_.diffusion[size_t(s)];
  if (d == 0.0 || thetaDt == 0.0) return SolverResult{true, 0, 0.0};
  Diffusion& df = *diffusion_[size_t(s)];
  if (rebuilt(s)) {  // rebuilt every step from this step's operator: I + theta dt d A
    if (!df.A) {
      df.A = std::make_unique<GpuLaplace>(up_.operators[size_t(s)]->shifted(thetaDt * d));
      df.A->setPrecision(real_);
      df.pcg = std::make_unique<GpuPcg>(*df.A, pcgWork_);
    }
    const double k = thetaDt * d / (up_.h * up_.h);
    df.A->assignShifted(*operator_[size_t(s)], k);
    df.thetaDt = thetaDt;
  } else if (df.thetaDt != thetaDt) {
    df.host = up_.operators[size_t(s)]->shifted(thetaDt * d);
    if (df.A)
      df.A->update(df.host);
    else
      df.A = std::make_unique<GpuLaplace>(df.host);
    df.A->setPrecision(real_);
    df.pcg = std::make_unique<GpuPcg>(*df.A, pcgWork_);
    // multigrid once diffusion dominates the identity, the diagonal below
    const double scale = thetaDt * d / (up_.h * up_.h);
    df.M = scale > 1.0
               ? std::make_unique<GpuMultigrid>(Multigrid<D>(df.host.axis, kDiffusionCycle), *df.A, kDiffusionCycle)
               : nullptr;
    df.thetaDt = thetaDt;
  }
  GpuBuffer& b = x_[size_t(s)];
  GpuBuffer& x = work_;
  // the Dirichlet ghost adds theta dt d 2 g / h^2 per boundary face
  if (up_.settings.boundary == RDBoundary::Dirichlet)
    vectorOp(VectorOp::AddFaces, faces_[size_t(s)], &b,
             thetaDt * d / (up_.h * up_.h) * 2.0 * up_.settings.dirichletValues[size_t(s)], 1.0);
  // warm start: b plus the last change, rescaled to this theta dt
  x.copyFrom(b, n_ * realBytes(real_));
  if (df.hasIncrement) vectorOp(VectorOp::ScaleAdd, df.increment, &x, thetaDt / df.incrementThetaDt, 1.0);
  const SolverResult r = df.pcg->solve(&b, &x, df.M.get(), {up_.settings.tolerance, 2000}, true);
  df.increment.copyFrom(x, n_ * realBytes(real_));
  vectorOp(VectorOp::ScaleAdd, b, &df.increment, -1.0, 1.0);
  df.incrementThetaDt = thetaDt;
  df.hasIncrement = true;
  std::swap(x_[size_t(s)], work_);
  return r;
}

// The GPU's stages of the layer's step, whose order is rd/rd_step.h's.
template <int D>
struct GpuRDLayer<D>::Stages {
  GpuRDLayer& l;

  void begin() {
    l.stats_ = RDStepStats{};
    l.stats_.diffusion.converged = true;
    if (l.frozenTaken_) return;  // frozen species keep the values they start the run with
    for (int s = 0; s < l.species_; ++s)
      if (l.isFrozen_[size_t(s)]) {
        l.frozen_[size_t(s)] = realBuffer(l.n_, l.real_);
        l.frozen_[size_t(s)].copyFrom(l.x_[size_t(s)], l.n_ * realBytes(l.real_));
      }
    l.frozenTaken_ = true;
  }
  bool dynamicTensor() const { return l.up_.tensor && l.up_.tensor->dynamic(); }
  void buildTensor() { l.buildTensor(); }
  bool lobes() const { return bool(l.up_.lobes); }
  void buildLobes() { l.buildLobes(); }
  void react(double dt, bool implicit) { l.react(dt, implicit); }
  void lendWork() {}
  void giveWork() {}
  int species() const { return l.species_; }
  double diffusion(int s) const { return l.up_.diffusion[size_t(s)]; }
  void explicitPart(int s, double dt, double explicitD, bool implicit) {
    const size_t k = size_t(s);
    if (explicitD > 0) l.operator_[k]->apply(l.x_[k], &l.work_);  // A x = -lap x (less the ghosts)
    if (implicit) return;
    const bool dirichlet = l.up_.settings.boundary == RDBoundary::Dirichlet;
    const double ghost = dirichlet ? 2.0 * l.up_.settings.dirichletValues[k] / (l.up_.h * l.up_.h) : 0.0;
    l.thetaStep(l.rates_[k], &l.x_[k], l.work_, dirichlet ? l.faces_[k] : l.work_, dt, explicitD, ghost);
  }
  SolverResult diffuse(int s, double thetaDt) { return l.diffuse(s, thetaDt); }
  void fold(const SolverResult& r) { foldWorst(&l.stats_.diffusion, r); }
  void clampSpecies() {
    for (int s = 0; s < l.species_; ++s)
      if ((l.clamped_ >> s) & 1u) l.vectorOp(VectorOp::ClampZero, l.x_[size_t(s)], &l.x_[size_t(s)], 0.0, 0.0);
  }
  void holdFixed() { l.holdFixed(); }
  void advanceClock(double) {
    ++l.steps_;
    if (l.up_.settings.integrator == RDIntegrator::KimLin) l.stats_.newton.cells = long(l.n_);
    if (statsDue(l.steps_)) l.readStats();
  }
};

template <int D>
void GpuRDLayer<D>::step(double dt) {
  Stages stages{*this};
  stepReactionDiffusion(stages, up_.settings.integrator, dt);
}

template <int D>
void GpuRDLayer<D>::readStats() {
  // The diffusion solves' tallies, and Newton's failures and most
  // iterations since the last read (the sums and maxima of the steps between).
  for (const auto& df : diffusion_)
    if (df && df->pcg) foldWorst(&stats_.diffusion, df->pcg->tally());
  if (up_.settings.integrator == RDIntegrator::KimLin) {
    const std::vector<uint32_t> st = stats_buffer_.read<uint32_t>(2);
    stats_.newton.failures = long(st[0]);
    stats_.newton.maxIterations = int(st[1]);
    stats_buffer_.zero();
  }
}

template <int D>
void GpuRDLayer<D>::lobeKernel(LobeMode mode, int species, GpuLaplace* target, GpuBuffer* faces) {
  const CosineLobeSpec& spec = *up_.lobes;
  const ComputeProgram& p =
      useProgram("rd_lobes.comp", fmt::format("#define DIM {}\n#define {}", D, define(mode)), real_);
  std::array<int, 3> dims{1, 1, 1};
  for (int a = 0; a < D; ++a) dims[size_t(a)] = up_.cells[a];
  setUniform(p, "dims", dims);
  setUniform(p, "periodic", up_.settings.boundary == RDBoundary::Periodic ? 1 : 0);
  setUniform(p, "dirichlet", up_.settings.boundary == RDBoundary::Dirichlet ? 1 : 0);
  setUniform(p, "witkinKass", spec.witkinKass ? 1 : 0);
  setUniform(p, "rotated", spec.theta0.empty() ? 0 : 1);
  const int lobes = int(spec.speeds.size());
  setUniform(p, "lobes", lobes);
  std::array<double, 8> speeds{};
  std::array<double, 16> centres{};
  for (int m = 0; m < lobes && m < 8; ++m) {
    speeds[size_t(m)] = spec.speeds[size_t(m)];
    centres[size_t(2 * m)] = std::cos(2.0 * M_PI * m / lobes);
    centres[size_t(2 * m + 1)] = std::sin(2.0 * M_PI * m / lobes);
  }
  setUniformDoubles(p, "speeds", speeds.data(), 8);
  setUniformDoubles(p, "centres", centres.data(), 16);
  setUniform(p, "meanA", meanLobeDiffusivity(spec));
  x_[size_t(species)].bind(0);
  lobeA_.bind(1);
  for (int a = 0; a < 3; ++a) target->weights(a < D ? a : 0).bind(2 + a);
  target->cBuffer().bind(5);
  (faces ? *faces : lobeA_).bind(7);
  rot_.bind(8);
  dispatchFlat(n_, 8.0 + 4.0 * (D + 2));
  storageBarrier();
}

template <int D>
bool GpuRDLayer<D>::rebuilt(int s) const {
  const DiffusionTensorSpec<D>* t = up_.tensor;
  return up_.lobed[size_t(s)] || (t && t->dynamic() && up_.anisotropic[size_t(s)]);
}

template <int D>
void GpuRDLayer<D>::tensorKernel(TensorMode mode, GpuLaplace* target) {
  const DiffusionTensorSpec<D>& spec = *up_.tensor;
  const ComputeProgram& p =
      useProgram("rd_tensor.comp", fmt::format("#define DIM {}\n#define {}", D, define(mode)), real_);
  std::array<int, 3> dims{1, 1, 1};
  for (int a = 0; a < D; ++a) dims[size_t(a)] = up_.cells[a];
  setUniform(p, "dims", dims);
  setUniform(p, "periodic", up_.settings.boundary == RDBoundary::Periodic ? 1 : 0);
  setUniform(p, "dirichlet", up_.settings.boundary == RDBoundary::Dirichlet ? 1 : 0);
  setUniform(p, "shape", spec.shape);
  setUniform(p, "floorFraction", kMinPrincipalFraction);
  const int mixed = D == 3 ? 6 : 2;
  x_[size_t(spec.shapeSpecies)].bind(0);
  direction_.bind(1);
  lambda1_.bind(2);
  lambda2_.bind(3);
  sigma_.bind(4);
  if (target) {
    for (int a = 0; a < 3; ++a) target->weights(a < D ? a : 0).bind(5 + a);
    target->cBuffer().bind(8);
    for (int q = 0; q < mixed; ++q) target->crossBuffer(q).bind(10 + q);
  }
  dispatchFlat(n_, 8.0 * AnisotropicSystem<D>::kComponents + 4.0 * (D + 1 + mixed));
  storageBarrier();
}

template <int D>
void GpuRDLayer<D>::buildTensor() {
  tensorKernel(TensorMode::Sigma, nullptr);
  for (int s = 0; s < species_; ++s) {
    if (!up_.anisotropic[size_t(s)]) continue;
    GpuLaplace* op = operator_[size_t(s)].get();
    faces_[size_t(s)].bind(9);
    tensorKernel(TensorMode::Faces, op);
    op->recomputeDiagonal();
  }
}

template <int D>
void GpuRDLayer<D>::buildLobes() {
  for (int s = 0; s < species_; ++s) {
    if (!up_.lobed[size_t(s)]) continue;
    GpuLaplace* op = operator_[size_t(s)].get();
    lobeKernel(LobeMode::A, s, op, nullptr);
    lobeKernel(LobeMode::Faces, s, op, &faces_[size_t(s)]);
    op->recomputeDiagonal();
  }
}

template <int D>
void GpuRDLayer<D>::holdFixed() {
  for (int s = 0; s < species_; ++s) {
    const size_t si = size_t(s);
    if (isFrozen_[si]) vectorOp(VectorOp::Hold, frozen_[si], &x_[si], 0.0, 0.0, &allHeld_);
    if (isFixed_[si]) vectorOp(VectorOp::Hold, fixedValue_[si], &x_[si], 0.0, 0.0, &fixedMask_[si]);
  }
}

template <int D>
void GpuRDLayer<D>::upload(int s, const std::vector<double>& values) {
  uploadReals(&x_[size_t(s)], values, real_);
}

template <int D>
std::vector<double> GpuRDLayer<D>::download(int s) const {
  return readReals(x_[size_t(s)], n_, real_);
}

template <int D>
void GpuRDLayer<D>::save(StateWriter* out) const {
  for (int s = 0; s < species_; ++s) {
    const Diffusion& df = *diffusion_[size_t(s)];
    const std::string p = "gpu.rd." + std::to_string(s) + ".";
    out->put(p + "has_increment", df.hasIncrement ? 1 : 0);
    out->put(p + "increment_theta_dt", df.incrementThetaDt);
    if (df.hasIncrement) out->putVector(p + "increment", readReals(df.increment, n_, real_));
    if (isFrozen_[size_t(s)] && frozenTaken_) out->putVector(p + "frozen", readReals(frozen_[size_t(s)], n_, real_));
  }
  out->put("gpu.rd.frozen_taken", frozenTaken_ ? 1 : 0);
}

template <int D>
void GpuRDLayer<D>::load(const StateReader& in) {
  for (int s = 0; s < species_; ++s) {
    Diffusion& df = *diffusion_[size_t(s)];
    const std::string p = "gpu.rd." + std::to_string(s) + ".";
    int has = 0;
    in.get(p + "has_increment", &has);
    in.get(p + "increment_theta_dt", &df.incrementThetaDt);
    df.hasIncrement = has != 0;
    if (df.hasIncrement) {
      std::vector<double> v(n_);
      in.getVector(p + "increment", &v);
      uploadReals(&df.increment, v, real_);
    }
  }
  int taken = 0;
  in.get("gpu.rd.frozen_taken", &taken);
  frozenTaken_ = taken != 0;
  for (int s = 0; s < species_ && frozenTaken_; ++s)
    if (isFrozen_[size_t(s)]) {
      std::vector<double> v(n_);
      in.getVector("gpu.rd." + std::to_string(s) + ".frozen", &v);
      frozen_[size_t(s)] = realBuffer(v, real_);
    }
}

template class GpuRDLayer<2>;
template class GpuRDLayer<3>;

}  // namespace morphoflow
