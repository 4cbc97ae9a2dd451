#include "rd/rd_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/jacobi.h"
#include "core/mic0.h"
#include "core/multigrid.h"
#include "core/parallel.h"

namespace morphoflow {

namespace {
constexpr size_t kChunk = 4096;  // cells per reaction task (fixed: results do not depend on threads)
}

template <int D>
struct RDSolver<D>::Diffusion {
  LaplaceSystem<D> A;  // I - theta dt d lap, as c x + sum w (x_i - x_j)
  std::unique_ptr<Preconditioner> M;
  PcgWorkspace ws;
  Vector x;
  double thetaDt = -1.0;
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

  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[size_t(a)] = s.boundary == RDBoundary::Periodic;
  laplacian_ = LaplaceSystem<D>(cells_, periodic, 1.0 / (h_ * h_));
  boundaryFaces_.assign(laplacian_.size(), 0.0);
  forEachCell<D>(cells_, [&](const IVec<D>& k, size_t i) {
    int faces = 0;
    for (int a = 0; a < D; ++a) {
      laplacian_.w[a][i] = 1.0f;  // finalize() cuts the wrap on non-periodic axes
      if (!periodic[size_t(a)]) faces += (k[a] == 0) + (k[a] == cells_[a] - 1);
    }
    if (s.boundary == RDBoundary::Dirichlet) {
      boundaryFaces_[i] = faces;
      laplacian_.c[i] = float(2 * faces);
    }
  });
  laplacian_.finalize();
  if (s.boundary == RDBoundary::Dirichlet && int(s.dirichletValues.size()) != n)
    throw std::invalid_argument("rd: Dirichlet boundaries need one value per species");
  for (int sp = 0; sp < n; ++sp) diffusion_.push_back(std::make_unique<Diffusion>());
  scratch_.assign(size_t(n), Vector(laplacian_.size(), 0.0));
  rates_.assign(size_t(n), Vector(laplacian_.size(), 0.0));
}

template <int D>
RDSolver<D>::~RDSolver() = default;

template <int D>
void RDSolver<D>::setParameterField(int k, std::vector<double> values) {
  if (values.size() != laplacian_.size()) throw std::invalid_argument("rd: parameter field has the wrong size");
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
double RDSolver<D>::explicitDiffusionLimit() const {
  double dmax = *std::max_element(d_.begin(), d_.end());
  return dmax > 0 ? h_ * h_ / (2.0 * D * dmax) : INFINITY;
}

template <int D>
void RDSolver<D>::applyLaplacian(int s, const Vector& x, Vector* out) const {
  laplacian_.apply(x, out);
  Vector& o = *out;
  const double g = settings_.boundary == RDBoundary::Dirichlet ? settings_.dirichletValues[size_t(s)] : 0.0;
  const double k = 2.0 * g / (h_ * h_);
  parallelFor(o.size(), [&](size_t i) { o[i] = -o[i] + k * boundaryFaces_[i]; }, kChunk);
}

// Solves (I - theta_dt d lap) x = rhs in place; the Dirichlet ghost adds
// theta_dt d 2 g / h^2 per boundary face to the right-hand side.
template <int D>
void RDSolver<D>::solveDiffusion(int s, double thetaDt, Vector* rhs) {
  const double d = d_[size_t(s)];
  if (d == 0.0 || thetaDt == 0.0) return;
  Diffusion& df = *diffusion_[size_t(s)];
  const double scale = thetaDt * d / (h_ * h_);
  if (df.thetaDt != thetaDt) {
    // x + scale (c_b x + sum (x_i - x_j)): unit scale with w = scale keeps the
    // identity exact (c = 1 away from Dirichlet walls), so a zero-flux run
    // conserves mass to round-off.
    df.A = laplacian_;
    df.A.scale = 1.0;
    for (int a = 0; a < D; ++a)
      for (size_t i = 0; i < df.A.size(); ++i) df.A.w[a][i] = laplacian_.w[a][i] * float(scale);
    for (size_t i = 0; i < df.A.size(); ++i) df.A.c[i] = float(1.0 + scale * laplacian_.c[i]);
    df.A.finalize();
    // MIC(0) on request; else multigrid once diffusion dominates the identity
    // (scale > 1), Jacobi below, where the system is diagonally dominant.
    if (settings_.linearSolver == RDLinearSolver::ICPCG)
      df.M = std::make_unique<MIC0Preconditioner<D>>(df.A);
    else if (scale > 1.0)
      df.M = std::make_unique<Multigrid<D>>(df.A);
    else
      df.M = std::make_unique<JacobiPreconditioner<D>>(df.A);
    df.thetaDt = thetaDt;
  }
  Vector& b = *rhs;
  if (settings_.boundary == RDBoundary::Dirichlet) {
    const double k = scale * 2.0 * settings_.dirichletValues[size_t(s)];
    parallelFor(b.size(), [&](size_t i) { b[i] += k * boundaryFaces_[i]; }, kChunk);
  }
  df.x = b;  // warm start: the undiffused state
  SolverOptions o{settings_.tolerance, 2000};
  SolverResult r = solvePCG<D>(df.A, b, &df.x, df.M.get(), o, nullptr, &df.ws);
  std::swap(b, df.x);
  SolverResult& w = stats_.diffusion;
  w.converged = w.converged && r.converged;
  w.iterations = std::max(w.iterations, r.iterations);
  w.residual = std::max(w.residual, r.residual);
}

template <int D>
void RDSolver<D>::react(double dt, bool implicit) {
  const int n = species();
  const size_t cells = laplacian_.size();
  const size_t chunks = (cells + kChunk - 1) / kChunk;
  double* xs[ReactionModel::kMaxSpecies];
  double* rs[ReactionModel::kMaxSpecies];
  for (int s = 0; s < n; ++s) {
    xs[s] = x_[size_t(s)].data();
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

template <int D>
void RDSolver<D>::step(double dt) {
  if (!(dt > 0)) throw std::invalid_argument("rd: dt must be > 0");
  const int n = species();
  if (steps_ == 0) {
    frozenValues_.assign(size_t(n), {});
    for (int s : settings_.frozen) frozenValues_[size_t(s)] = x_[size_t(s)].values();
  }
  stats_ = RDStepStats{};
  stats_.diffusion.converged = true;
  const size_t cells = laplacian_.size();
  // Every integrator is a theta scheme on the diffusion,
  //   (1 - theta dt d lap) x' = x + dt R + (1 - theta) dt d lap x,
  // with R = R(x) lagged, or for Kim & Lin the implicit reaction step first.
  const RDIntegrator integ = settings_.integrator;
  const bool implicitReaction = integ == RDIntegrator::KimLin;
  const double theta = integ == RDIntegrator::ExplicitEuler ? 0.0 : integ == RDIntegrator::CrankNicolson ? 0.5 : 1.0;
  react(dt, implicitReaction);  // Kim & Lin: updates x in place (projected per cell)
  for (int s = 0; s < n; ++s) {
    Vector& x = x_[size_t(s)].values();
    const Vector &L = scratch_[size_t(s)], &R = rates_[size_t(s)];
    const double explicitD = (1.0 - theta) * dt * d_[size_t(s)];
    // The explicit part carries its Dirichlet term inside L; the implicit
    // part adds its own through solveDiffusion.
    if (explicitD > 0) applyLaplacian(s, x, &scratch_[size_t(s)]);
    if (!implicitReaction && explicitD > 0)
      parallelFor(cells, [&](size_t i) { x[i] += dt * R[i] + explicitD * L[i]; }, kChunk);
    else if (!implicitReaction)
      parallelFor(cells, [&](size_t i) { x[i] += dt * R[i]; }, kChunk);
    solveDiffusion(s, theta * dt, &x);
  }
  for (int s : model_.info().clamped) {
    Grid<double, D>& g = x_[size_t(s)];
    parallelFor(cells, [&](size_t i) { g[i] = std::max(g[i], 0.0); }, kChunk);
  }
  holdFixed();
  time_ += dt;
  ++steps_;
}

template class RDSolver<2>;
template class RDSolver<3>;

}  // namespace morphoflow
