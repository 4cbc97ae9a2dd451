#include "rd/rd_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/bfloat16.h"
#include "core/chebyshev.h"
#include "core/jacobi.h"
#include "core/mic0.h"
#include "core/multigrid.h"
#include "core/parallel.h"
#include "core/work_pool.h"
#include "rd/rd_step.h"

namespace morphoflow {

namespace {
constexpr size_t kChunk = 4096;  // cells per reaction task (fixed: results do not depend on threads)
}

template <int D>
struct RDSolver<D>::Diffusion {
  AnisotropicSystem<D> A;  // I - theta dt d lap, as c x + sum w (x_i - x_j) (+ diagonal pairs)
  std::unique_ptr<Chebyshev<D>> chebyshev;  // for an operator without mixed terms
  bool useChebyshev = false;                 // it solves instead of PCG: it is the quicker
  std::unique_ptr<Preconditioner> M;
  // The last solve's x - b: the next one's warm start (a guess only, so
  // bfloat16: 2 bytes a cell).
  std::vector<uint16_t> increment;
  double incrementThetaDt = 0.0;  // the theta dt it was made over
  double thetaDt = -1.0;
  long version = -1;  // tensor version it was built from
};

template <int D>
RDSolver<D>::RDSolver(const RDSettings& s, const ReactionModel& model) : settings_(s), model_(model) {
  const ModelInfo& info = model.info();
  const int n = model.species();
  if (int(s.resolution.size()) != D || int(s.size.size()) != D)
    throw std::invalid_argument("rd: resolution and size need " + std::to_string(D) + " entries");
  for (int a = 0; a < D; ++a) {
    if (s.resolution[size_t(a)] < 2) throw std::invalid_argument("rd: at least 2 cells per axis");
    cells_[a] = s.resolution[size_t(a)];
  }
  h_ = s.size[0] / cells_[0];
  d_ = s.diffusion.empty() ? info.diffusion : s.diffusion;
  if (int(d_.size()) != n) throw std::invalid_argument("rd: one diffusion rate per species");
  for (double d : d_)
    if (!(d >= 0)) throw std::invalid_argument("rd: diffusion rates must be >= 0");
  params_.constant.clear();
  for (const ParameterInfo& p : info.parameters) params_.constant.push_back(p.value);
  if (!s.parameters.empty()) {
    if (s.parameters.size() != info.parameters.size()) throw std::invalid_argument("rd: one value per parameter");
    params_.constant = s.parameters;
  }
  params_.field.assign(params_.constant.size(), nullptr);
  fields_.assign(params_.constant.size(), {});
  for (int sp = 0; sp < n; ++sp) x_.emplace_back(cells_, info.initial[size_t(sp)]);

  cellCount_ = x_[0].size();
  if (s.boundary == RDBoundary::Dirichlet) {
    boundaryFaces_.assign(cellCount_, 0.0);
    forEachCell<D>(cells_, [&](const IVec<D>& k, size_t i) {
      int faces = 0;
      for (int a = 0; a < D; ++a) faces += (k[a] == 0) + (k[a] == cells_[a] - 1);
      boundaryFaces_[i] = faces;
    });
  }
  // The Laplacian itself is built only where something applies it (an
  // explicit part, the GPU backend): the implicit systems are built directly.
  lapBound_ = AnisotropicSystem<D>(isotropicSystem(std::nullopt)).maxRowAbsSum();
  if (s.boundary == RDBoundary::Dirichlet && int(s.dirichletValues.size()) != n)
    throw std::invalid_argument("rd: Dirichlet boundaries need one value per species");
  for (int sp = 0; sp < n; ++sp) diffusion_.push_back(std::make_unique<Diffusion>());
  // Sized where an integrator uses them (Kim & Lin's implicit reaction and
  // diffusion need neither).
  rates_.assign(size_t(n), Vector());
}

template <int D>
LaplaceSystem<D> RDSolver<D>::isotropicSystem(std::optional<double> shift) const {
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[size_t(a)] = settings_.boundary == RDBoundary::Periodic;
  // -h^2 lap: w = 1, c = 2 per Dirichlet face, scale 1 / h^2; shifted by s
  // (AnisotropicSystem::shifted's arithmetic): I + s lap with k = s / h^2,
  // w = k, c = 1 + k c, scale 1.
  const double k = shift ? *shift * (1.0 / (h_ * h_)) : 1.0;
  LaplaceSystem<D> lap(cells_, periodic, shift ? 1.0 : 1.0 / (h_ * h_));
  const float w = shift ? float(double(1.0f) * k) : 1.0f;
  const bool dirichlet = settings_.boundary == RDBoundary::Dirichlet;
  parallelFor(lap.size(), [&](size_t i) {
    for (int a = 0; a < D; ++a) lap.w[a].at(i) = w;  // finalize() cuts the wrap on non-periodic axes
    const float c = dirichlet ? float(2.0 * boundaryFaces_[i]) : 0.0f;
    lap.c.at(i) = shift ? float(1.0 + k * double(c)) : c;
  }, kChunk);
  lap.finalize();
  return lap;
}

template <int D>
const AnisotropicSystem<D>& RDSolver<D>::laplacian() const {
  if (!laplacian_) laplacian_ = std::make_unique<AnisotropicSystem<D>>(isotropicSystem(std::nullopt));
  return *laplacian_;
}

template <int D>
RDSolver<D>::~RDSolver() = default;

template <int D>
void RDSolver<D>::setParameterField(int k, std::vector<double> values) {
  if (values.size() != cellCount_) throw std::invalid_argument("rd: parameter field has the wrong size");
  fields_[size_t(k)] = std::move(values);
  params_.field[size_t(k)] = fields_[size_t(k)].data();
  lut_ = ReactionLUT();
}

template <int D>
void RDSolver<D>::setFixedCells(std::vector<std::vector<uint8_t>> masks, std::vector<std::vector<double>> values) {
  fixedMasks_ = std::move(masks);
  fixedValues_ = std::move(values);
}

template <int D>
void RDSolver<D>::setDiffusionTensor(DiffusionTensorSpec<D> spec) {
  if (lobeSpec_) throw std::invalid_argument("rd: a diffusion tensor and cosine lobes cannot be combined");
  const size_t cells = cellCount_;
  for (int a = 0; a < D; ++a)
    if (spec.direction[size_t(a)].size() != cells)
      throw std::invalid_argument("rd: tensor direction has the wrong size");
  if (spec.lambda1.size() != cells || spec.lambda2.size() != cells)
    throw std::invalid_argument("rd: principal diffusivities have the wrong size");
  for (size_t i = 0; i < cells; ++i)
    if (!(spec.lambda1[i] > 0) || !(spec.lambda2[i] > 0))
      throw std::invalid_argument("rd: principal diffusivities must be > 0 (sigma positive definite)");
  if (spec.dynamic() && (spec.shapeSpecies < 0 || spec.shapeSpecies >= species()))
    throw std::invalid_argument("rd: the shape species is out of range");
  tensorSpecies_.assign(size_t(species()), spec.species.empty() ? 1 : 0);
  for (int s : spec.species) {
    if (s < 0 || s >= species()) throw std::invalid_argument("rd: anisotropic species out of range");
    tensorSpecies_[size_t(s)] = 1;
  }
  tensorSpec_ = std::make_unique<DiffusionTensorSpec<D>>(std::move(spec));
  buildTensor();
}

template <int D>
void RDSolver<D>::setGeneralizedDiffusion(std::shared_ptr<const GeneralizedDiffusion> op, std::vector<int> species) {
  if (D != 2 || settings_.boundary != RDBoundary::Periodic)
    throw std::invalid_argument("generalized diffusion is for periodic 2D layers");
  general_ = std::move(op);
  generalSpecies_.assign(size_t(this->species()), species.empty() ? 1 : 0);
  for (int s : species) generalSpecies_[size_t(s)] = 1;
}

template <int D>
void RDSolver<D>::setCosineLobes(CosineLobeSpec spec) {
  if (tensorSpec_) throw std::invalid_argument("rd: a diffusion tensor and cosine lobes cannot be combined");
  validateCosineLobes(spec);
  if (!spec.theta0.empty() && spec.theta0.size() != cellCount_)
    throw std::invalid_argument("rd: the lobes' theta0 field has the wrong size");
  lobeSpecies_.assign(size_t(species()), spec.species.empty() ? 1 : 0);
  for (int s : spec.species) {
    if (s < 0 || s >= species()) throw std::invalid_argument("rd: lobed species out of range");
    lobeSpecies_[size_t(s)] = 1;
  }
  lobeSpec_ = std::make_unique<CosineLobeSpec>(std::move(spec));
  lobeSystem_.assign(size_t(species()), AnisotropicSystem<D>());
  lobeBoundary_.assign(size_t(species()), Vector());
  buildLobes();
}

// -h^2 div(sigma grad), the Dirichlet ghosts weighted by sigma_aa.
template <int D>
void RDSolver<D>::assemble(const std::array<std::vector<double>, AnisotropicSystem<D>::kComponents>& sigma,
                           AnisotropicSystem<D>* system, Vector* boundary) const {
  std::array<const double*, AnisotropicSystem<D>::kComponents> ptr;
  for (size_t k = 0; k < sigma.size(); ++k) ptr[k] = sigma[k].data();
  std::array<bool, D> per{};
  per.fill(settings_.boundary == RDBoundary::Periodic);
  *system = AnisotropicSystem<D>::fromTensor(cells_, per, 1.0 / (h_ * h_), ptr);
  boundary->assign(system->size(), 0.0);
  if (settings_.boundary == RDBoundary::Dirichlet) {
    system->axis.c.densify();
    forEachCell<D>(cells_, [&](const IVec<D>& k, size_t i) {
      double w = 0.0;
      for (int a = 0; a < D; ++a) w += sigma[size_t(a)][i] * ((k[a] == 0) + (k[a] == cells_[a] - 1));
      (*boundary)[i] = w;
      system->axis.c.at(i) = float(2.0 * w);
    });
    system->axis.finalize();
  }
}

// sigma from the spec (and the shape species' current gradient).
template <int D>
void RDSolver<D>::buildTensor() {
  const DiffusionTensorSpec<D>& spec = *tensorSpec_;
  const bool periodic = settings_.boundary == RDBoundary::Periodic;
  assemble(diffusionTensor<D>(spec, cells_, periodic, spec.dynamic() ? &x_[size_t(spec.shapeSpecies)] : nullptr),
           &tensor_, &tensorBoundary_);
  ++operatorVersion_;
}

// a(theta) I per lobed species, theta from that species' own gradient (eq. 14, 17).
template <int D>
void RDSolver<D>::buildLobes() {
  const bool periodic = settings_.boundary == RDBoundary::Periodic;
  for (int s = 0; s < species(); ++s)
    if (lobed(s))
      assemble(lobeTensor<D>(*lobeSpec_, x_[size_t(s)], periodic), &lobeSystem_[size_t(s)], &lobeBoundary_[size_t(s)]);
  ++operatorVersion_;
}

template <int D>
double RDSolver<D>::explicitDiffusionLimit() const {
  double worst = 0.0;
  const double lapBound = lapBound_;
  const double tensorBound = tensorSpec_ ? tensor_.maxRowAbsSum() : 0.0;
  // a(theta) <= max a_n, so lobes are bounded by the Laplacian's bound times that.
  const double lobeBound = lobeSpec_ ? lapBound * maxLobeDiffusivity(*lobeSpec_) : 0.0;
  double generalBound = 0.0;  // Gershgorin for the 5 x 5 kernel, in -h^2 A's units
  if (general_)
    for (const auto& row : general_->kernel())
      for (double k : row) generalBound += std::abs(k) * h_ * h_;
  for (int s = 0; s < species(); ++s)
    worst = std::max(worst, d_[size_t(s)] * (generalized(s) ? generalBound
                                             : lobed(s)     ? lobeBound
                                             : anisotropic(s) ? tensorBound
                                                              : lapBound));
  return worst > 0 ? 2.0 * h_ * h_ / worst : INFINITY;
}

template <int D>
void RDSolver<D>::applyLaplacian(int s, const Vector& x, Vector* out) const {
  if (generalized(s)) return general_->apply(x, out);  // seed 000 eq. 37
  diffusionOperator(s).apply(x, out);
  Vector& o = *out;
  if (settings_.boundary != RDBoundary::Dirichlet) {
    parallelFor(o.size(), [&](size_t i) { o[i] = -o[i]; }, kChunk);
    return;
  }
  const double k = 2.0 * settings_.dirichletValues[size_t(s)] / (h_ * h_);
  const Vector& faces = boundaryWeights(s);
  parallelFor(o.size(), [&](size_t i) { o[i] = -o[i] + k * faces[i]; }, kChunk);
}

// Solves (I - theta_dt d lap) x = rhs in place; the Dirichlet ghost adds
// theta_dt d 2 g / h^2 per boundary face to the right-hand side.
template <int D>
SolverResult RDSolver<D>::solveDiffusion(int s, double thetaDt, Vector* rhs) {
  const double d = d_[size_t(s)];
  if (d == 0.0 || thetaDt == 0.0) return SolverResult{true, 0, 0.0};
  if (generalized(s)) return general_->solve(thetaDt * d, rhs, settings_.tolerance);  // eq. 28
  Diffusion& df = *diffusion_[size_t(s)];
  const double scale = thetaDt * d / (h_ * h_);
  const long version = anisotropic(s) || lobed(s) ? operatorVersion_ : 0;
  if (df.thetaDt != thetaDt || df.version != version) {
    // x + scale (c_b x + sum (x_i - x_j)): unit scale with w = scale keeps the
    // identity exact (c = 1 away from Dirichlet walls), so a zero-flux run
    // conserves mass to round-off.
    if (anisotropic(s) || lobed(s))
      df.A = diffusionOperator(s).shifted(thetaDt * d);
    else {
      df.A = AnisotropicSystem<D>();  // free the old one first
      df.A = AnisotropicSystem<D>(isotropicSystem(thetaDt * d));
    }
    // The default solver takes the Chebyshev iteration where it is the
    // quicker (an isotropic operator, diffusion not too far beyond the
    // identity: core/chebyshev.h). Else PCG: with MIC(0) on request; else
    // multigrid once diffusion dominates the identity (scale > 1), Jacobi
    // below, where the system is diagonally dominant. With a tensor they
    // precondition the axis part (the mixed terms are bounded by it for a
    // positive definite sigma). A multigrid hierarchy of the same shape (a
    // new dt: only the coefficients changed) is re-derived in place.
    auto* mg = dynamic_cast<Multigrid<D>*>(df.M.get());
    const bool chebyshev = settings_.linearSolver == RDLinearSolver::MGPCG && !df.A.hasCross;
    if (chebyshev && df.chebyshev)
      df.chebyshev->refresh();  // it reads df.A.axis, assigned in place above
    else if (chebyshev)
      df.chebyshev = std::make_unique<Chebyshev<D>>(df.A.axis, ChebyshevLayout{}, &chebyshevWork_);
    df.useChebyshev = chebyshev && df.chebyshev->quick();
    if (df.useChebyshev)
      df.M.reset();
    else if (settings_.linearSolver == RDLinearSolver::ICPCG)
      df.M = std::make_unique<MIC0Preconditioner<D>>(df.A.axis);
    else if (scale > 1.0 && mg)
      mg->refresh();
    else if (scale > 1.0)
      df.M = std::make_unique<Multigrid<D>>(df.A.axis, kDiffusionCycle);
    else
      df.M = std::make_unique<JacobiPreconditioner<D>>(df.A.axis);
    df.thetaDt = thetaDt;
    df.version = version;
  }
  Vector& b = *rhs;
  if (settings_.boundary == RDBoundary::Dirichlet) {
    const double k = scale * 2.0 * settings_.dirichletValues[size_t(s)];
    const Vector& faces = boundaryWeights(s);
    parallelFor(b.size(), [&](size_t i) { b[i] += k * faces[i]; }, kChunk);
  }
  // Warm start: the undiffused state plus the last step's diffusive change
  // (rescaled to this theta dt), which a slowly evolving pattern repeats, as
  // the fluid's viscosity does. The same pass forms ||b|| for the Chebyshev
  // iteration (norm2's sum, so bitwise its value).
  Vector& x = solveX_;  // shared: the species are solved one after another
  resizeExactly(&x, b.size());
  double bnorm = -1.0;  // not known: the solver computes it
  if (df.increment.size() == b.size()) {
    const double ratio = thetaDt / df.incrementThetaDt;
    bnorm = std::sqrt(deterministicSum(b.size(), [&](size_t i) {
      x[i] = b[i] + ratio * double(fromBfloat16(df.increment[i]));
      return b[i] * b[i];
    }));
  } else {
    x = b;
  }
  SolverOptions o{settings_.tolerance, 2000};
  SolverResult r = df.useChebyshev ? df.chebyshev->solve(b, &x, o, bnorm)
                                   : solvePCG<D>(df.A, b, &x, df.M.get(), o, &pcgWork_);
  df.increment.resize(b.size());
  parallelFor(b.size(), [&](size_t i) { df.increment[i] = toBfloat16(float(x[i] - b[i])); }, kChunk);
  df.incrementThetaDt = thetaDt;
  std::swap(b, x);
  return r;
}

template <int D>
void RDSolver<D>::react(double dt, bool implicit) {
  const int n = species();
  const size_t cells = cellCount_;
  const size_t chunks = (cells + kChunk - 1) / kChunk;
  double* xs[ReactionModel::kMaxSpecies];
  double* rs[ReactionModel::kMaxSpecies];
  for (int s = 0; s < n; ++s) {
    xs[s] = x_[size_t(s)].data();
    if (!implicit) rates_[size_t(s)].resize(cells);
    rs[s] = rates_[size_t(s)].data();
  }
  if (!implicit) {  // rates_ = R(x)
    parallelFor(chunks, [&](size_t c) {
      model_.evaluate(xs, params_, rs, c * kChunk, std::min(cells, (c + 1) * kChunk));
    });
    return;
  }
  const bool useLut = settings_.lookupTable && n == 2 && params_.uniform();
  if (useLut && (!lut_.valid() || lut_.dt() != dt)) {
    const ModelInfo& in = model_.info();
    lut_.build(model_, params_.constant.data(), dt, in.lutLow, in.lutHigh, settings_.lookupSize);
  }
  std::vector<NewtonStats> per(chunks);
  std::vector<int> hits(chunks, 0);
  parallelFor(chunks, [&](size_t c) {
    size_t begin = c * kChunk, end = std::min(cells, (c + 1) * kChunk);
    if (!useLut) {
      per[c] = model_.implicitUpdate(xs, params_, dt, begin, end);
      return;
    }
    for (size_t i = begin; i < end; ++i) {
      double x0[2] = {xs[0][i], xs[1][i]}, x1[2];
      if (lut_.lookup(x0, x1)) {
        xs[0][i] = x1[0];
        xs[1][i] = x1[1];
        ++hits[c];
      } else {
        per[c].merge(model_.implicitUpdate(xs, params_, dt, i, i + 1));
      }
    }
  });
  for (size_t c = 0; c < chunks; ++c) {
    stats_.newton.merge(per[c]);
    stats_.lookups += hits[c];
  }
}

template <int D>
void RDSolver<D>::holdFixed() {
  for (int s : settings_.frozen) {
    Grid<double, D>& g = x_[size_t(s)];
    std::copy(frozenValues_[size_t(s)].begin(), frozenValues_[size_t(s)].end(), g.values().begin());
  }
  for (size_t s = 0; s < fixedMasks_.size(); ++s) {
    if (fixedMasks_[s].empty()) continue;
    Grid<double, D>& g = x_[s];
    const std::vector<double>& v = fixedValues_[s];
    const std::vector<uint8_t>& mask = fixedMasks_[s];
    parallelFor(g.size(), [&](size_t i) { if (mask[i]) g[i] = v[i]; }, kChunk);
  }
}

// The CPU's stages of the layer's step, whose order is rd/rd_step.h's.
template <int D>
struct RDSolver<D>::Stages {
  RDSolver& r;
  // f(doubles, floats) on the solvers' work vectors, which the pool lends
  // for the species' solves.
  template <class F>
  void work(F&& f) {
    if (!r.pool_) return;
    const std::initializer_list<Vector*> doubles = {&r.solveX_, &r.pcgWork_.b, &r.pcgWork_.r, &r.pcgWork_.p,
                                                    &r.pcgWork_.q};
    const std::initializer_list<std::vector<float>*> floats = {&r.chebyshevWork_.e[0], &r.chebyshevWork_.e[1],
                                                               &r.chebyshevWork_.g};
    f(doubles, floats);
  }

  void begin() {
    if (r.steps_ == 0) {
      r.frozenValues_.assign(size_t(r.species()), {});
      for (int s : r.settings_.frozen) r.frozenValues_[size_t(s)] = r.x_[size_t(s)].values();
    }
    r.stats_ = RDStepStats{};
    r.stats_.diffusion.converged = true;
  }
  bool dynamicTensor() const { return r.tensorSpec_ && r.tensorSpec_->dynamic(); }
  void buildTensor() { r.buildTensor(); }
  bool lobes() const { return bool(r.lobeSpec_); }
  void buildLobes() { r.buildLobes(); }
  void react(double dt, bool implicit) { r.react(dt, implicit); }  // Kim & Lin: x in place (projected per cell)
  void lendWork() {
    work([&](auto doubles, auto floats) { r.pool_->lend(doubles), r.pool_->lend(floats); });
  }
  void giveWork() {
    work([&](auto doubles, auto floats) { r.pool_->give(doubles), r.pool_->give(floats); });
  }
  int species() const { return r.species(); }
  double diffusion(int s) const { return r.d_[size_t(s)]; }
  // The explicit part carries its Dirichlet term inside L; the implicit part
  // adds its own through solveDiffusion.
  void explicitPart(int s, double dt, double explicitD, bool implicitReaction) {
    const size_t cells = r.cellCount_;
    Vector& x = r.x_[size_t(s)].values();
    const Vector &L = r.scratch_, &R = r.rates_[size_t(s)];
    if (explicitD > 0) {
      r.scratch_.resize(cells);
      r.applyLaplacian(s, x, &r.scratch_);
    }
    if (!implicitReaction && explicitD > 0)
      parallelFor(cells, [&](size_t i) { x[i] += dt * R[i] + explicitD * L[i]; }, kChunk);
    else if (!implicitReaction)
      parallelFor(
          cells, [&](size_t i) { x[i] += dt * R[i]; }, kChunk);
  }
  SolverResult diffuse(int s, double thetaDt) { return r.solveDiffusion(s, thetaDt, &r.x_[size_t(s)].values()); }
  void fold(const SolverResult& result) { foldWorst(&r.stats_.diffusion, result); }
  void clampSpecies() {
    for (int s : r.model_.info().clamped) {
      Grid<double, D>& g = r.x_[size_t(s)];
      parallelFor(
          r.cellCount_, [&](size_t i) { g[i] = std::max(g[i], 0.0); }, kChunk);
    }
  }
  void holdFixed() { r.holdFixed(); }
  void advanceClock(double dt) {
    r.time_ += dt;
    ++r.steps_;
  }
};

template <int D>
void RDSolver<D>::step(double dt) {
  if (!(dt > 0)) throw std::invalid_argument("rd: dt must be > 0");
  Stages stages{*this};
  stepReactionDiffusion(stages, settings_.integrator, dt);
}

template <int D>
void RDSolver<D>::save(StateWriter* out) const {
  out->put("rd.time", time_);
  out->put("rd.steps", steps_);
  for (int s = 0; s < species(); ++s) {
    const std::string p = "rd." + std::to_string(s) + ".";
    const Diffusion& df = *diffusion_[size_t(s)];
    out->putGrid(p + "x", x_[size_t(s)]);
    out->put(p + "increment_size", df.increment.size());
    out->putVector(p + "increment_bf16", df.increment);
    out->put(p + "increment_theta_dt", df.incrementThetaDt);
    out->put(p + "frozen_size", s < int(frozenValues_.size()) ? frozenValues_[size_t(s)].size() : size_t(0));
    if (s < int(frozenValues_.size())) out->putVector(p + "frozen", frozenValues_[size_t(s)]);
  }
}

template <int D>
void RDSolver<D>::load(const StateReader& in) {
  in.get("rd.time", &time_);
  in.get("rd.steps", &steps_);
  frozenValues_.assign(size_t(species()), {});
  for (int s = 0; s < species(); ++s) {
    const std::string p = "rd." + std::to_string(s) + ".";
    Diffusion& df = *diffusion_[size_t(s)];
    in.getGrid(p + "x", &x_[size_t(s)]);
    size_t n = 0;
    in.get(p + "increment_size", &n);
    df.increment.assign(n == 0 ? 0 : cellCount_, 0);
    in.getVector(p + "increment_bf16", &df.increment);
    for (uint16_t h : df.increment)
      if (!std::isfinite(fromBfloat16(h)))
        throw StateError("section '" + p + "increment_bf16' holds a non-finite value");
    in.get(p + "increment_theta_dt", &df.incrementThetaDt);
    in.get(p + "frozen_size", &n);
    frozenValues_[size_t(s)].assign(n == 0 ? 0 : cellCount_, 0.0);
    if (n) in.getVector(p + "frozen", &frozenValues_[size_t(s)]);
  }
}

template class RDSolver<2>;
template class RDSolver<3>;

}  // namespace morphoflow
