#include "fluid/viscosity.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/masked_select.h"
#include "core/parallel.h"
#include "core/work_pool.h"

namespace morphoflow {

namespace {

// Rows [lo, hi) (unknown coordinates) of component a's system: each
// unknown's couplings, and the terms walls, prescribed faces and cut
// obstacles add (written in place while dense; a compact system's rows
// are written again without a pass over the rest: core/row_field.h).
template <int D>
void viscousRows(ViscousSystem<D>* system, const VelocityConstraints<D>& vc, int a, const IVec<D>& lo,
                 const IVec<D>& hi) {
  ViscousSystem<D>& C = *system;
  const std::array<bool, D> periodic = vc.periodic();
  const Grid<uint8_t, D>& fixed = vc.fixed[a];
  // With cut obstacles, the distance to them at the faces a cut obstacle
  // closes in part (the only ones whose centre can lie inside); +infinity
  // (outside) elsewhere.
  const bool cut = !vc.cut.empty();
  auto distance = [&](const IVec<D>& k) { return float(vc.cut.distance(vc.facePosition(a, k).data())); };
  auto phiAt = [&](const IVec<D>& k) {
    return vc.open[a](k) < 1.0f ? distance(k) : std::numeric_limits<float>::infinity();
  };
  // phi over the box and one layer round it, found once (each face's is read
  // by its 2 D neighbours too); a wrapped neighbour outside it finds its own.
  IVec<D> plo, pdims;
  size_t boxSize = 1;
  for (int b = 0; b < D; ++b) {
    plo[b] = std::max(lo[b] - 1, 0);
    pdims[b] = std::max(std::min(hi[b] + 1, C.dims[b]) - plo[b], 0);
    boxSize *= size_t(pdims[b]);
  }
  std::vector<float> phiBox(cut ? boxSize : 0);
  if (cut) forEachCell<D>(pdims, [&](const IVec<D>& r, size_t i) { phiBox[i] = phiAt(plo + r); });
  auto phi = [&](const IVec<D>& k) {
    for (int b = 0; b < D; ++b)
      if (k[b] < plo[b] || k[b] >= plo[b] + pdims[b]) return phiAt(k);
    return phiBox[latticeIndex<D>(pdims, k - plo)];
  };
  if (cut && C.insideCut.size() != C.A.size()) C.insideCut.assign(C.A.size(), 0);
  std::array<RowField<D>*, D + 2> fields;
  for (int bx = 0; bx < D; ++bx) fields[size_t(bx)] = &C.A.w[bx];
  fields[D] = &C.cBoundary;
  fields[D + 1] = &C.boundaryRhs;
  rewriteRows<D, D + 2>(fields, rowsOf<D>(C.dims, lo, hi), [&](size_t row, const std::array<float*, D + 2>& v) {
    IVec<D> k = latticeCoord<D>(C.dims, row * size_t(C.dims[0]));
    for (k[0] = lo[0]; k[0] < hi[0]; ++k[0]) {
      const int x = k[0];
      const size_t i = C.A.c.index(k);
      for (int bx = 0; bx < D; ++bx) v[size_t(bx)][x] = 0.0f;
      if (cut) C.insideCut[i] = 0;
      v[D + 1][x] = 0.0f;
      const size_t gi = fixed.index(k);
      if (fixed[gi] || (cut && phi(k) < 0.0f)) {
        if (!fixed[gi]) C.insideCut[i] = 1;
        v[D][x] = -1.0f;
        continue;
      }
      double c = 0.0, extra = 0.0;
      for (int bx = 0; bx < D; ++bx) {
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[bx] += dir;
          if (nb[bx] < 0 || nb[bx] >= C.dims[bx]) {
            if (periodic[size_t(bx)]) {
              nb[bx] = (nb[bx] + C.dims[bx]) % C.dims[bx];
            } else {
              if (bx == a) continue;  // an outflow face: zero gradient
              const DomainSide& side = vc.boundaries.side(bx, dir > 0);
              if (side.kind == BoundaryKind::Outflow) continue;
              // Ghost mirrored about the wall: u_g = 2 u_wall - u.
              double uw = side.kind == BoundaryKind::Wall ? side.wallVelocity[size_t(a)] : 0.0;
              c += 2.0;
              extra += 2.0 * uw;
              continue;
            }
          }
          const size_t ni = fixed.index(nb);
          const float phiNb = cut ? phi(nb) : 0.0f;
          if (cut && phiNb < 0.0f) {
            // Gibou et al. 2002: the obstacle's velocity at the surface, a
            // fraction theta of the way to the neighbour.
            const double theta = cutTheta(distance(k), phiNb);
            c += 1.0 / theta;
            if (vc.bodies.moving()) {
              std::array<double, 3> xs = vc.facePosition(a, k);
              xs[size_t(bx)] += dir * theta * vc.h;
              extra += vc.bodies.velocity(xs.data(), a) / theta;
            }
          } else if (fixed[ni]) {
            c += 1.0;
            extra += double(vc.prescribed(a, ni));
          } else if (dir > 0) {
            v[size_t(bx)][x] = 1.0f;
          }
        }
      }
      v[D][x] = float(c);  // whole: 2 per wall ghost, 1 per prescribed neighbour, 1/theta per cut one
      v[D + 1][x] = float(extra);
    }
  });
}

}  // namespace

template <int D>
ViscousSystem<D> viscousSystem(const VelocityConstraints<D>& vc, int a) {
  ViscousSystem<D> C;
  const IVec<D>& n = vc.cells;
  // Unknowns: the face grid, less the duplicate face n_a on a periodic axis.
  C.dims = n + unitVector<D>(a);
  if (vc.periodic()[size_t(a)]) C.dims[a] = n[a];
  C.A = LaplaceSystem<D>(C.dims, vc.periodic(), 1.0);
  C.cBoundary = RowField<D>(C.dims, 0.0f);
  C.boundaryRhs = RowField<D>(C.dims, 0.0f);
  viscousRows<D>(&C, vc, a, IVec<D>(0), C.dims);
  C.cBoundary.compact();
  C.boundaryRhs.compact();
  C.A.finalize();  // the weights compacted now; c follows at setRate
  return C;
}

template <int D>
void updateViscousSystem(ViscousSystem<D>* C, const VelocityConstraints<D>& vc, int a, const IVec<D>& lo,
                         const IVec<D>& hi, IVec<D>* ulo, IVec<D>* uhi) {
  IVec<D> from, to;
  for (int b = 0; b < D; ++b) {
    from[b] = std::max(lo[b] - 1, 0);
    to[b] = std::min(hi[b] + (b == a ? 2 : 1), C->dims[b]);
  }
  viscousRows<D>(C, vc, a, from, to);  // (compact rows stay compact; c, the diagonal and the spans follow at setRate)
  if (ulo) *ulo = from;
  if (uhi) *uhi = to;
}

template <int D>
void ViscositySolver<D>::rebuild(const IVec<D>& lo, const IVec<D>& hi) {
  // (the solvers refer to C.A, whose coefficients change, not its shape)
  // (the components' systems and solvers are their own: rebuilt at once)
  parallelTasks(size_t(D), [&](size_t a) {
    Component& C = comp_[a];
    // (the last move's rows: a resumed run places its obstacles at its
    // time before the step, and relaxes what an uninterrupted one does)
    updateViscousSystem<D>(&C, vc_, int(a), lo, hi, &C.movedLo, &C.movedHi);
    if (s_ < 0.0) return;  // (no rate yet: the whole system follows at the first solve)
    C.setRateRows(C.movedLo, C.movedHi);
    refreshSolvers(C, &C.movedLo, &C.movedHi);
  });
}

namespace {
// c of an unknown at rate s from its boundary terms (-1: prescribed, inactive).
inline float rateTerm(double s, float cBoundary) {
  return cBoundary < 0.0f ? 0.0f : float(1.0 / s + double(cBoundary));
}
}  // namespace

template <int D>
void ViscousSystem<D>::setRate(double s) {
  A.scale = s;
  A.c = cBoundary;  // its rows, mapped: no full-size field
  A.c.transform([s](float cb) { return rateTerm(s, cb); });
  A.finalize();
}

template <int D>
void ViscousSystem<D>::setRateRows(const IVec<D>& lo, const IVec<D>& hi) {
  const double s = A.scale;
  rewriteRows<D, 1>({&A.c}, rowsOf<D>(dims, lo, hi), [&](size_t row, const std::array<float*, 1>& c) {
    const float* cb = cBoundary.row(row);
    for (int x = 0; x < dims[0]; ++x) c[0][x] = rateTerm(s, cb[x]);
  });
  A.finalizeRows(lo, hi);
}

template <int D>
ViscositySolver<D>::ViscositySolver(const VelocityConstraints<D>& vc, const SolverOptions& options)
    : vc_(vc), options_(options) {
  for (int a = 0; a < D; ++a) {
    Component& C = comp_[size_t(a)];
    static_cast<ViscousSystem<D>&>(C) = viscousSystem<D>(vc_, a);
  }
}

namespace {
// Three smoothing sweeps each way: the identity term makes the viscous
// systems better conditioned than the pressure's, and with the sweeps in one
// pass over memory a third sweep costs less than the outer iteration it
// saves (measured at 512^2, 64^3 and 128^3: docs/performance.md).
const MultigridOptions kViscosityCycle{3, 3, 4};
// Red-black sweeps on the rows a moving obstacle rewrote, before a solve.
constexpr int kMovedSweeps = 2;
}  // namespace

// One row of component a's unknowns as the passes below read it: unknown
// i0 + x is face g0 + x of its grid (the same index unless a periodic axis
// drops the duplicate face layer), held where fixed[x] | cut[x] (its face
// prescribed, or inside a cut obstacle), so the loops over a row have no
// branches.
struct UnknownRow {
  size_t row, i0, g0;
  const uint8_t* fixed;  // the face's flag
  const uint8_t* cut;    // inside a cut obstacle (a row of zeros without one)
};
template <int D>
static UnknownRow unknownRow(const ViscousSystem<D>& C, const Grid<uint8_t, D>& fixed, const Grid<float, D>& g,
                             size_t row) {
  thread_local std::vector<uint8_t> none;  // the cut flags without cut obstacles
  if (C.insideCut.empty() && none.size() < size_t(C.dims[0])) none.assign(size_t(C.dims[0]), 0);
  const size_t i0 = row * size_t(C.dims[0]), g0 = g.index(latticeCoord<D>(C.dims, i0));
  return UnknownRow{row, i0, g0, fixed.data() + g0, C.insideCut.empty() ? none.data() : C.insideCut.data() + i0};
}
// fn(UnknownRow) on every row, in parallel.
template <int D>
static void eachRowOf(const ViscousSystem<D>& C, const Grid<uint8_t, D>& fixed, const Grid<float, D>& g, auto&& fn) {
  forEachRow<D>(C.dims, [&](size_t row, const IVec<D>&) { fn(unknownRow<D>(C, fixed, g, row)); });
}

// One row of b = u* + s (boundary terms), 0 on held unknowns, to b.
template <int D>
static void rhsRow(const ViscousSystem<D>& C, const UnknownRow& r, const Grid<float, D>& g, double s,
                   double* __restrict b) {
  const float* __restrict rhs = C.boundaryRhs.row(r.row);
  const float* __restrict gr = g.data() + r.g0;
  const uint8_t* __restrict f = r.fixed, * __restrict c = r.cut;
  const size_t nx = size_t(C.dims[0]);
  for (size_t x = 0; x < nx; ++x) b[x] = zeroWhere(f[x] | c[x], double(gr[x]) + s * double(rhs[x]));
}

template <int D>
double ViscositySolver<D>::rightHandSideSquared(const MacVelocity<D>& u, int a, double s) const {
  const Component& C = comp_[size_t(a)];
  const Grid<float, D>& g = u[a];
  const Grid<uint8_t, D>& fixed = vc_.fixed[a];
  const size_t nx = size_t(C.dims[0]);
  // dot(b, b)'s chunks and order, each chunk's rows formed in a buffer.
  return deterministicChunkSum(C.A.size(), [&](size_t begin, size_t end) {
    thread_local std::vector<double> rows;
    const size_t r0 = begin / nx, r1 = (end + nx - 1) / nx;
    rows.resize((r1 - r0) * nx);
    for (size_t row = r0; row < r1; ++row) rhsRow<D>(C, unknownRow<D>(C, fixed, g, row), g, s, &rows[(row - r0) * nx]);
    const double* b = rows.data() + (begin - r0 * nx);
    auto square = [b](size_t i) { return b[i] * b[i]; };
    return orderedSum(size_t(0), end - begin, square);
  });
}

template <int D>
SolverResult ViscositySolver<D>::diffuse(MacVelocity<D>* u, double nu, double dt, WorkPool* pool) {
  if (nu <= 0 || dt <= 0) {
    cellUpdates_ = 0.0;
    return SolverResult{true, 0, 0.0};
  }
  const std::initializer_list<Vector*> doubles = {&b_, &x_, &pcgWork_.b, &pcgWork_.r, &pcgWork_.p, &pcgWork_.q};
  const std::initializer_list<std::vector<float>*> floats = {&chebyshevWork_.e[0], &chebyshevWork_.e[1],
                                                             &chebyshevWork_.g};
  if (pool) pool->lend(doubles), pool->lend(floats);
  const SolverResult result = solveComponents(u, nu * dt / (vc_.h * vc_.h));
  if (pool) pool->give(doubles), pool->give(floats);
  return result;
}

template <int D>
void ViscositySolver<D>::refreshSolvers(Component& C, const IVec<D>* lo, const IVec<D>* hi) {
  if (!C.chebyshev) C.chebyshev = std::make_unique<Chebyshev<D>>(C.A, ChebyshevLayout{}, &chebyshevWork_);
  else C.chebyshev->refresh();
  if (C.chebyshev->quick()) C.multigrid.reset();
  else if (!C.multigrid) C.multigrid = std::make_unique<Multigrid<D>>(C.A, kViscosityCycle);
  else if (lo) C.multigrid->refresh(*lo, *hi);
  else C.multigrid->refresh();
}

template <int D>
SolverResult ViscositySolver<D>::solveComponents(MacVelocity<D>* u, double s) {
  SolverResult result;
  result.converged = true;
  cellUpdates_ = 0.0;
  usedCG_ = false;
  std::array<double, D> bb{};  // ||b_a||^2
  for (int a = D - 1; a >= 0; --a) {  // last: component 0, the first solved
    Component& C = comp_[size_t(a)];
    if (s != s_) {  // A = s (c + sum w (x_i - x_j)), c = 1/s + boundary terms
      C.setRate(s);
      refreshSolvers(C);
    }
    bb[size_t(a)] = rightHandSideSquared(*u, a, s);
  }
  // The D systems are blocks of one linear system, (I - nu dt lap) u = u*
  // on the MAC velocity, solved to a relative residual of that system:
  // sum_a ||r_a||^2 <= tol^2 sum_a ||b_a||^2. Block a may leave
  // ||r_a||^2 <= tol^2 (||b_a||^2 + ||b||^2 / D) / 2 (these budgets add up
  // to tol^2 ||b||^2), so a component much smaller than the flow (the
  // cross-flow of a lid that has just started) is not solved to 1e-6 of its
  // own size, which would cost iterations and buy nothing.
  double bAll = 0.0;
  for (double v : bb) bAll += v;
  double rAll = 0.0;
  for (int a = 0; a < D; ++a) {
    Component& C = comp_[size_t(a)];
    Grid<float, D>& g = (*u)[a];
    const Grid<uint8_t, D>& fixed = vc_.fixed[a];
    const double ba = bb[size_t(a)];
    // Warm start: the increment's rate, linearly extrapolated in steps
    // (2 r1 - r0 = r1 + (r1 - r0)) where kExtrapolates, else the last
    // rate; in the same pass, the right-hand side.
    const int history = C.history;
    resizeExactly(&x_, C.A.size());
    resizeExactly(&b_, C.A.size());
    eachRowOf<D>(C, fixed, g, [&](const UnknownRow& r) {
      const float* __restrict gr = g.data() + r.g0;
      const uint8_t* __restrict f = r.fixed, * __restrict c = r.cut;
      double* __restrict x = x_.data() + r.i0;
      const size_t nx = size_t(C.dims[0]);
      rhsRow<D>(C, r, g, s, b_.data() + r.i0);
      if (history == 0) {
        for (size_t k = 0; k < nx; ++k)
          x[k] = zeroWhere(f[k] | c[k], double(gr[k]) + s * 0.0);  // (a zero rate: -0 -> +0)
        return;
      }
      const float* __restrict rate = C.rate.data() + r.i0;
      if constexpr (!kExtrapolates) {
        for (size_t k = 0; k < nx; ++k) x[k] = zeroWhere(f[k] | c[k], double(gr[k]) + s * double(rate[k]));
      } else {
        const uint16_t* __restrict change = C.change.data() + r.i0;
        const double second = history >= 2 ? 1.0 : 0.0;  // the change counts from the second solve on
        for (size_t k = 0; k < nx; ++k) {
          const double v = double(gr[k]) + s * (double(rate[k]) + second * double(fromBfloat16(change[k])));
          x[k] = zeroWhere(f[k] | c[k], v);
        }
      }
    });
    // The warm start comes from solves on the rows before a moving obstacle
    // rewrote them, and leaves its largest residuals on them (a face whose
    // cut distance changed, one the solid uncovered): two red-black sweeps
    // there (at 128^3 the circling sphere's Chebyshev steps fall from 32.4
    // to 22.7-24.2, the body at rest's 22.0-23.5; docs/performance.md).
    C.A.relaxBox(b_, &x_, C.movedLo, C.movedHi, kMovedSweeps);
    C.movedLo = C.movedHi = IVec<D>(0);
    SolverOptions options = options_;
    if (ba > 0.0) options.tolerance = options_.tolerance * std::sqrt(0.5 * (ba + bAll / D) / ba);
    const SolverResult r = C.multigrid ? solvePCG<D>(C.A, b_, &x_, C.multigrid.get(), options, &pcgWork_)
                                       : C.chebyshev->solve(b_, &x_, options, std::sqrt(ba));
    rAll += r.residual * r.residual * ba;
    result.iterations = std::max(result.iterations, r.iterations);
    cellUpdates_ += double(r.iterations) * (C.multigrid ? double(C.A.size()) : C.chebyshev->cellsPerStep());
    usedCG_ = usedCG_ || C.multigrid != nullptr;
    std::vector<float>& rate = C.rate;
    rate.resize(C.A.size(), 0.0f);  // zeros before the first solve: change = the first rate, unused
    if (kExtrapolates) C.change.resize(C.A.size());
    const double invS = 1.0 / s;
    eachRowOf<D>(C, fixed, g, [&](const UnknownRow& r) {
      float* __restrict gr = g.data() + r.g0;
      const uint8_t* __restrict f = r.fixed, * __restrict c = r.cut;
      const double* __restrict x = x_.data() + r.i0;
      float* __restrict rt = rate.data() + r.i0;
      uint16_t* __restrict change = kExtrapolates ? C.change.data() + r.i0 : nullptr;
      const size_t nx = size_t(C.dims[0]);
      for (size_t k = 0; k < nx; ++k) {
        const bool held = f[k] | c[k];
        const float next = zeroWhere(held, float((x[k] - double(gr[k])) * invS));
        if (kExtrapolates) change[k] = toBfloat16(next - rt[k]);
        rt[k] = next;
        gr[k] = pick(held, gr[k], float(x[k]));
      }
    });
    C.history = std::min(C.history + 1, kExtrapolates ? 2 : 1);
  }
  result.residual = bAll > 0.0 ? std::sqrt(rAll / bAll) : 0.0;
  result.converged = result.residual <= options_.tolerance * 1.0001;
  s_ = s;
  vc_.apply(u);
  return result;
}

template <int D>
void ViscositySolver<D>::save(StateWriter* out) const {
  for (int a = 0; a < D; ++a) {
    const std::string p = "viscosity." + std::to_string(a) + ".";
    const Component& C = comp_[size_t(a)];
    out->put(p + "history", C.history);
    if (C.history >= 1) out->putVector(p + "rate", C.rate);
    if (kExtrapolates && C.history >= 2) out->putVector(p + "change", C.change);
  }
}

template <int D>
void ViscositySolver<D>::load(const StateReader& in) {
  for (int a = 0; a < D; ++a) {
    Component& C = comp_[size_t(a)];
    const std::string p = "viscosity." + std::to_string(a) + ".";
    in.get(p + "history", &C.history);
    C.rate.assign(C.A.size(), 0.0f);
    C.history = std::min(C.history, kExtrapolates ? 2 : 1);  // (a change the checkpoint holds beyond: not read)
    if (kExtrapolates) C.change.resize(C.A.size());
    if (C.history >= 1) in.getVector(p + "rate", &C.rate);
    if (kExtrapolates && C.history >= 2) in.getVector(p + "change", &C.change);
  }
}

template struct ViscousSystem<2>;
template struct ViscousSystem<3>;
template ViscousSystem<2> viscousSystem<2>(const VelocityConstraints<2>&, int);
template void updateViscousSystem<2>(ViscousSystem<2>*, const VelocityConstraints<2>&, int, const IVec<2>&,
                                     const IVec<2>&, IVec<2>*, IVec<2>*);
template void updateViscousSystem<3>(ViscousSystem<3>*, const VelocityConstraints<3>&, int, const IVec<3>&,
                                     const IVec<3>&, IVec<3>*, IVec<3>*);
template ViscousSystem<3> viscousSystem<3>(const VelocityConstraints<3>&, int);
template class ViscositySolver<2>;
template class ViscositySolver<3>;

}  // namespace morphoflow
