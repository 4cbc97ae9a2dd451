// Manufactured Poisson solutions: every solver reproduces the analytic
// solution to the discretisation error, which falls at second order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>

#include "core/laplace_system.h"
#include "core/mic0.h"
#include "core/multigrid.h"
#include "core/parallel.h"
#include "core/pcg.h"
#include "core/simd_dispatch.h"

using namespace morphoflow;

namespace {

enum class Method { MGPCG, ICPCG, Multigrid, CG };
const double kPi = 3.14159265358979323846;

// -lap(u) = f on [0,1]^D with u = 0 on the walls (Dirichlet through a
// mirrored ghost: c += 2 on boundary cells).
template <int D>
LaplaceSystem<D> dirichletSystem(int n) {
  IVec<D> dims(n);
  double h = 1.0 / n;
  LaplaceSystem<D> A(dims, {}, 1.0 / (h * h));
  for (int a = 0; a < D; ++a) A.w[a].fill(1.0f);
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    for (int a = 0; a < D; ++a) {
      if (k[a] == 0) A.c.at(i) += 2.0f;
      if (k[a] == n - 1) A.c.at(i) += 2.0f;
    }
  });
  A.finalize();
  return A;
}

template <int D>
SolverResult solveWith(Method m, const LaplaceSystem<D>& A, const Vector& b, Vector* x, double tol) {
  SolverOptions o{tol, 2000};
  switch (m) {
    case Method::MGPCG: {
      Multigrid<D> mg(A);
      return solvePCG<D>(A, b, x, &mg, o);
    }
    case Method::ICPCG: {
      MIC0Preconditioner<D> mic(A);
      return solvePCG<D>(A, b, x, &mic, o);
    }
    case Method::Multigrid: {
      Multigrid<D> mg(A);
      return mg.solve(b, x, o);
    }
    case Method::CG:
      return solvePCG<D>(A, b, x, nullptr, o);
  }
  return {};
}

// Max error against the analytic solution, after a manufactured solve.
template <int D>
double manufacturedError(Method m, int n, bool neumann, SolverResult* res) {
  IVec<D> dims(n);
  double h = 1.0 / n;
  LaplaceSystem<D> A = neumann ? makeNeumannLaplacian<D>(dims, {}, h) : dirichletSystem<D>(n);
  Vector b(A.size()), exact(A.size()), x(A.size(), 0.0);
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    double u = 1.0;
    for (int a = 0; a < D; ++a) {
      double s = (k[a] + 0.5) * h;
      u *= neumann ? std::cos(kPi * s) : std::sin(kPi * s);
    }
    exact[i] = u;
    b[i] = D * kPi * kPi * u;
  });
  *res = solveWith<D>(m, A, b, &x, 1e-10);
  if (neumann) {  // compare up to the constant null space
    A.removeNullSpace(&x);
    A.removeNullSpace(&exact);
  }
  double err = 0;
  for (size_t i = 0; i < x.size(); ++i) err = std::max(err, std::abs(x[i] - exact[i]));
  return err;
}

}  // namespace

std::string solverCaseName(const ::testing::TestParamInfo<std::tuple<Method, bool>>& info) {
  static const char* names[] = {"MGPCG", "ICPCG", "Multigrid", "CG"};
  return std::string(names[int(std::get<0>(info.param))]) + (std::get<1>(info.param) ? "_Neumann" : "_Dirichlet");
}

class ManufacturedPoisson : public ::testing::TestWithParam<std::tuple<Method, bool>> {};

TEST_P(ManufacturedPoisson, SecondOrderIn2D) {
  auto [method, neumann] = GetParam();
  SolverResult r1, r2;
  double e1 = manufacturedError<2>(method, 32, neumann, &r1);
  double e2 = manufacturedError<2>(method, 64, neumann, &r2);
  EXPECT_TRUE(r1.converged) << "residual " << r1.residual;
  EXPECT_TRUE(r2.converged) << "residual " << r2.residual;
  EXPECT_LT(e2, 2e-3);
  // Halving h divides the error by ~4 (second order).
  EXPECT_GT(e1 / e2, 3.5) << "errors " << e1 << " " << e2;
  EXPECT_LT(e1 / e2, 4.5) << "errors " << e1 << " " << e2;
}

TEST_P(ManufacturedPoisson, SecondOrderIn3D) {
  auto [method, neumann] = GetParam();
  SolverResult r1, r2;
  double e1 = manufacturedError<3>(method, 16, neumann, &r1);
  double e2 = manufacturedError<3>(method, 32, neumann, &r2);
  EXPECT_TRUE(r1.converged);
  EXPECT_TRUE(r2.converged);
  EXPECT_GT(e1 / e2, 3.3) << "errors " << e1 << " " << e2;
  EXPECT_LT(e1 / e2, 4.7) << "errors " << e1 << " " << e2;
}

INSTANTIATE_TEST_SUITE_P(Solvers, ManufacturedPoisson,
                         ::testing::Combine(::testing::Values(Method::MGPCG, Method::ICPCG,
                                                             Method::Multigrid, Method::CG),
                                            ::testing::Bool()),
                         solverCaseName);

// A Poisson system with a solid block and a periodic axis: all solvers agree,
// and multigrid preconditioning needs far fewer iterations than MIC(0).
TEST(LinearSolvers, ObstaclesAndPeriodicAxes) {
  IVec<2> dims(96, 64);
  double h = 1.0 / 64;
  LaplaceSystem<2> A(dims, {true, false}, 1.0 / (h * h));
  auto solid = [&](const IVec<2>& k) { return k[0] >= 30 && k[0] < 45 && k[1] >= 20 && k[1] < 40; };
  forEachCell<2>(dims, [&](const IVec<2>& k, size_t i) {
    if (solid(k)) return;
    IVec<2> r(k[0] + 1 == dims[0] ? 0 : k[0] + 1, k[1]);
    IVec<2> u(k[0], k[1] + 1);
    if (!solid(r)) A.w[0].at(i) = 1;
    if (u[1] < dims[1] && !solid(u)) A.w[1].at(i) = 1;
    if (k[1] == dims[1] - 1) A.c.at(i) = 2;  // Dirichlet top (an outflow)
  });
  A.finalize();
  ASSERT_FALSE(A.singular());
  Vector b(A.size());
  for (size_t i = 0; i < b.size(); ++i) b[i] = A.diag[i] > 0 ? std::sin(0.37 * double(i)) : 0.0;
  Vector x1(A.size(), 0.0), x2(A.size(), 0.0), x3(A.size(), 0.0);
  SolverResult r1 = solveWith<2>(Method::MGPCG, A, b, &x1, 1e-8);
  SolverResult r2 = solveWith<2>(Method::ICPCG, A, b, &x2, 1e-8);
  SolverResult r3 = solveWith<2>(Method::Multigrid, A, b, &x3, 1e-8);
  ASSERT_TRUE(r1.converged && r2.converged && r3.converged)
      << r1.iterations << " " << r1.residual << " / " << r3.iterations << " " << r3.residual;
  double scale = 0, d12 = 0, d13 = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    scale = std::max(scale, std::abs(x1[i]));
    d12 = std::max(d12, std::abs(x1[i] - x2[i]));
    d13 = std::max(d13, std::abs(x1[i] - x3[i]));
  }
  EXPECT_LT(d12, 1e-5 * scale);
  EXPECT_LT(d13, 1e-5 * scale);
  EXPECT_LT(r1.iterations * 3, r2.iterations) << "MGPCG " << r1.iterations << " vs ICPCG " << r2.iterations;
  for (size_t i = 0; i < b.size(); ++i)
    if (A.diag[i] == 0) {
      EXPECT_EQ(x1[i], 0.0);  // solid cells stay pinned
    }
}

TEST(LinearSolvers, MultigridPreconditionerIsSymmetric) {
  // <M^-1 a, b> == <a, M^-1 b>: required for PCG to converge. The cycle
  // runs in single precision, so symmetric to float round-off.
  IVec<3> dims(16, 12, 10);
  LaplaceSystem<3> A = makeNeumannLaplacian<3>(dims, {false, true, false}, 0.1);
  A.c.densify();
  forEachCell<3>(dims, [&](const IVec<3>& k, size_t i) { if (k[0] == 0) A.c.at(i) = 1.0f; });
  A.finalize();
  Multigrid<3> mg(A);
  Vector a(A.size()), b(A.size()), ma, mb;
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = std::sin(1.3 * double(i));
    b[i] = std::cos(0.7 * double(i) + 0.2);
  }
  mg.apply(a, &ma);
  mg.apply(b, &mb);
  double ab = dot(ma, b), ba = dot(a, mb);
  EXPECT_NEAR(ab, ba, 1e-5 * std::abs(ab));
}

// MGPCG keeps the coarse levels' vectors in PCG's q while it preconditions
// (q is dead then): the hierarchy allocates none of its own, and the solve
// is bitwise the one with the levels in vectors of their own.
template <int D>
void expectCoarseLevelsInTheScratch(int n) {
  LaplaceSystem<D> A = dirichletSystem<D>(n);
  A.w[0].densify();
  A.w[0].at(size_t(n) / 2) = 0.25f;  // a partial face, as an obstacle's
  A.finalize();
  Vector b(A.size());
  for (size_t i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * double(i)) + 0.1;
  const SolverOptions o{1e-8, 200};
  Multigrid<D> lent(A);
  Vector x1(A.size(), 0.0);
  const SolverResult r1 = solvePCG<D>(A, b, &x1, &lent, o);
  EXPECT_EQ(lent.coarseBytes(), 0u);
  // The same cycle through a preconditioner that takes no scratch.
  struct OwnVectors final : Preconditioner {
    explicit OwnVectors(Multigrid<D>* m) : mg(m) {}
    void apply(const Vector& r, Vector* z) override { mg->apply(r, z); }
    double applyDot(const Vector& r, double rnorm, Vector* z) override { return mg->applyDot(r, rnorm, z); }
    bool recomputesZ() const override { return true; }
    void direction(double beta, bool first, Vector* p) override { mg->direction(beta, first, p); }
    Multigrid<D>* mg;
  };
  Multigrid<D> own(A);
  OwnVectors wrapped(&own);
  Vector x2(A.size(), 0.0);
  const SolverResult r2 = solvePCG<D>(A, b, &x2, &wrapped, o);
  EXPECT_GT(own.coarseBytes(), 0u);
  EXPECT_TRUE(r1.converged);
  EXPECT_EQ(r1.iterations, r2.iterations);
  EXPECT_EQ(r1.residual, r2.residual);
  EXPECT_EQ(x1, x2);
}

TEST(LinearSolvers, MultigridCoarseLevelsLiveInTheSolversScratch) {
  expectCoarseLevelsInTheScratch<2>(96);
  expectCoarseLevelsInTheScratch<3>(32);
}

// A new identity term (a new time step of an implicit diffusion) with the
// levels re-derived in place must give bitwise the cycle of a hierarchy built
// from scratch, in 2D and 3D, with an obstacle-like partial face.
template <int D>
void expectRefreshMatchesRebuild(const IVec<D>& dims) {
  LaplaceSystem<D> A = makeNeumannLaplacian<D>(dims, {}, 1.0 / dims[0]);
  A.w[0].densify();
  A.w[0].at(7) = 0.5f;
  auto setIdentity = [&](double s) {
    A.c.densify();
    forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) { A.c.at(i) = float(1.0 / s + (k[1] == 0 ? 2.0 : 0.0)); });
    A.finalize();
  };
  setIdentity(1.5);
  Multigrid<D> kept(A);
  setIdentity(7.25);
  kept.refresh();
  Multigrid<D> fresh(A);
  ASSERT_EQ(kept.levels(), fresh.levels());
  for (int l = 1; l < kept.levels(); ++l) {
    EXPECT_EQ(kept.level(l).c.expanded(), fresh.level(l).c.expanded()) << "level " << l;
    EXPECT_EQ(kept.level(l).scale, fresh.level(l).scale);
  }
  Vector r(A.size()), z1, z2;
  for (size_t i = 0; i < r.size(); ++i) r[i] = std::sin(0.37 * double(i)) + 0.1;
  kept.apply(r, &z1);
  fresh.apply(r, &z2);
  EXPECT_EQ(z1, z2);
}

TEST(LinearSolvers, MultigridRefreshMatchesARebuild) {
  expectRefreshMatchesRebuild<2>(IVec<2>(40, 33));
  expectRefreshMatchesRebuild<3>(IVec<3>(20, 17, 12));
}

// Weights changed in a box only (an obstacle that moved), the levels
// re-derived over that box alone: bitwise every level of a hierarchy built
// from scratch, with the box inside, at a domain edge, and across a periodic
// axis's seam, in 2D and 3D.
template <int D>
void expectRegionalRefreshMatchesRebuild(const IVec<D>& dims, std::array<bool, D> periodic) {
  LaplaceSystem<D> A = makeNeumannLaplacian<D>(dims, periodic, 1.0 / dims[0]);
  Multigrid<D> kept(A);
  IVec<D> lo, hi;
  for (int corner = 0; corner < 3; ++corner) {
    for (int a = 0; a < D; ++a) {  // inside; touching the low edges; touching the high ones
      lo[a] = corner == 1 ? 0 : 3 + a;
      hi[a] = corner == 2 ? dims[a] : lo[a] + 5 + a;
    }
    for (int a = 0; a < D; ++a) A.w[a].densify();
    A.c.densify();
    forEachCell<D>(hi - lo, [&](const IVec<D>& r, size_t) {
      const IVec<D> k = lo + r;
      const size_t i = latticeIndex<D>(dims, k);
      A.c.at(i) = float(0.25 * (corner + 1) + 0.01 * double(i % 7));
      for (int a = 0; a < D; ++a) A.w[a].at(i) = float(0.125 * double((i + size_t(a) + size_t(corner)) % 9));
    });
    A.finalize();
    kept.refresh(lo, hi);
    Multigrid<D> fresh(A);
    ASSERT_EQ(kept.levels(), fresh.levels());
    for (int l = 1; l < kept.levels(); ++l) {
      EXPECT_EQ(kept.level(l).c.expanded(), fresh.level(l).c.expanded()) << "level " << l << ", box " << corner;
      EXPECT_EQ(kept.level(l).diag.expanded(), fresh.level(l).diag.expanded()) << "level " << l << ", box " << corner;
      for (int a = 0; a < D; ++a)
        EXPECT_EQ(kept.level(l).w[a].expanded(), fresh.level(l).w[a].expanded())
            << "level " << l << ", axis " << a << ", box " << corner;
    }
    Vector r(A.size()), z1, z2;
    for (size_t i = 0; i < r.size(); ++i) r[i] = std::sin(0.37 * double(i)) + 0.1;
    kept.apply(r, &z1);
    fresh.apply(r, &z2);
    EXPECT_EQ(z1, z2) << "box " << corner;
  }
}

TEST(LinearSolvers, MultigridRegionalRefreshMatchesARebuild) {
  expectRegionalRefreshMatchesRebuild<2>(IVec<2>(40, 33), {false, false});
  expectRegionalRefreshMatchesRebuild<2>(IVec<2>(40, 32), {true, false});
  expectRegionalRefreshMatchesRebuild<3>(IVec<3>(20, 17, 12), {false, false, false});
  expectRegionalRefreshMatchesRebuild<3>(IVec<3>(20, 16, 12), {true, false, true});
}

// Rows of a compact system written again in a box (an obstacle that
// moved), finalized over those rows alone: the diagonal, the spans, the
// singularity and every kernel bitwise those of a whole finalize(), with
// the box inside, at the low edges, at the high ones (across a periodic
// seam) and over everything, and with c > 0 coming and going (a singular
// system and not).
template <int D>
void expectRowFinalizeMatchesAWholeOne(const IVec<D>& dims, std::array<bool, D> periodic) {
  LaplaceSystem<D> A = makeNeumannLaplacian<D>(dims, periodic, 1.0 / dims[0]);
  for (int corner = 0; corner < 4; ++corner) {
    IVec<D> lo, hi;
    for (int a = 0; a < D; ++a) {  // inside; touching the low edges; touching the high ones; everything
      lo[a] = corner == 1 || corner == 3 ? 0 : 3 + a;
      hi[a] = corner == 2 || corner == 3 ? dims[a] : lo[a] + 5 + a;
    }
    std::array<RowField<D>*, D + 1> fields{&A.c};
    for (int a = 0; a < D; ++a) fields[size_t(a) + 1] = &A.w[a];
    rewriteRows<D, D + 1>(fields, rowsOf<D>(dims, lo, hi), [&](size_t row, const std::array<float*, D + 1>& v) {
      IVec<D> k = latticeCoord<D>(dims, row * size_t(dims[0]));
      for (k[0] = lo[0]; k[0] < hi[0]; ++k[0]) {
        const size_t i = latticeIndex<D>(dims, k);
        v[0][k[0]] = corner == 3 ? 0.0f : float(0.25 * corner * double(i % 3));  // the last box: none left
        for (int a = 0; a < D; ++a)
          v[size_t(a) + 1][k[0]] =
              k[a] == dims[a] - 1 && !periodic[a] ? 0.0f : float(0.125 * double((i + size_t(a) + corner) % 9));
      }
    });
    A.finalizeRows(lo, hi);
    LaplaceSystem<D> whole = A;
    whole.c.densify();
    for (int a = 0; a < D; ++a) whole.w[a].densify();
    whole.finalize();
    EXPECT_EQ(A.diag.expanded(), whole.diag.expanded()) << "box " << corner;
    EXPECT_EQ(A.singular(), whole.singular()) << "box " << corner;
    for (size_t row = 0; row < A.size() / size_t(dims[0]); ++row) {
      EXPECT_EQ(A.sweepSpan(row).lo, whole.sweepSpan(row).lo) << "row " << row << ", box " << corner;
      EXPECT_EQ(A.sweepSpan(row).hi, whole.sweepSpan(row).hi) << "row " << row << ", box " << corner;
    }
    Vector x(A.size()), y1(A.size()), y2(A.size()), b(A.size());
    for (size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.37 * double(i)) + 0.1, b[i] = std::cos(0.11 * double(i));
    EXPECT_EQ(A.applyDot(x, &y1), whole.applyDot(x, &y2)) << "box " << corner;
    EXPECT_EQ(y1, y2) << "box " << corner;
    Vector x1 = x, x2 = x;
    A.gaussSeidel(b, &x1, false);
    whole.gaussSeidel(b, &x2, false);
    EXPECT_EQ(x1, x2) << "box " << corner;
    A.removeNullSpace(&x1);
    whole.removeNullSpace(&x2);
    EXPECT_EQ(x1, x2) << "box " << corner;
  }
  EXPECT_TRUE(A.singular());  // the last box took every c > 0 away
}

TEST(LinearSolvers, RowFinalizeMatchesAWholeOne) {
  expectRowFinalizeMatchesAWholeOne<2>(IVec<2>(40, 33), {false, false});
  expectRowFinalizeMatchesAWholeOne<2>(IVec<2>(40, 32), {true, true});
  expectRowFinalizeMatchesAWholeOne<3>(IVec<3>(20, 17, 12), {false, false, false});
  expectRowFinalizeMatchesAWholeOne<3>(IVec<3>(20, 16, 12), {true, true, true});
}

TEST(LinearSolvers, ResultsIndependentOfThreadCount) {
  IVec<2> dims(128, 128);
  LaplaceSystem<2> A = makeNeumannLaplacian<2>(dims, {}, 1.0 / 128);
  Vector b(A.size());
  for (size_t i = 0; i < b.size(); ++i) b[i] = std::sin(0.01 * double(i)) + std::cos(0.003 * double(i));
  Vector x1(A.size(), 0.0), x2(A.size(), 0.0);
  {
    ThreadLimit t(1);
    solveWith<2>(Method::MGPCG, A, b, &x1, 1e-8);
  }
  {
    ThreadLimit t(2);
    solveWith<2>(Method::MGPCG, A, b, &x2, 1e-8);
  }
  EXPECT_EQ(x1, x2);
}

// A right-hand side near 1e-160 (a decaying species) must not underflow the
// inner products: the solution scales with b.
TEST(LinearSolvers, TinyRightHandSideSolvesToScale) {
  IVec<2> dims(32, 32);
  LaplaceSystem<2> A = makeNeumannLaplacian<2>(dims, {true, true}, 1.0 / 32);
  A.c.densify();
  for (size_t i = 0; i < A.size(); ++i) A.c.at(i) = 1.0f;
  A.finalize();
  Vector b(A.size()), big(A.size()), x(A.size(), 0.0), xt(A.size(), 0.0);
  for (size_t i = 0; i < b.size(); ++i) {
    big[i] = std::sin(0.3 * double(i));
    b[i] = 1e-160 * big[i];
  }
  SolverOptions o{1e-10, 500};
  SolverResult r1 = solvePCG<2>(A, big, &x, nullptr, o);
  SolverResult r2 = solvePCG<2>(A, b, &xt, nullptr, o);
  ASSERT_TRUE(r1.converged && r2.converged) << r2.residual;
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(xt[i] * 1e160, x[i], 1e-8 * std::abs(x[i]) + 1e-12);
}

// The multigrid cycle runs in single precision: right-hand sides far outside
// float's range (1e-60, 1e+60, as a decaying or exploding species gives)
// must still solve to scale, with MGPCG and with plain V-cycles.
TEST(LinearSolvers, SinglePrecisionMultigridSolvesAnyScale) {
  IVec<2> dims(64, 48);
  LaplaceSystem<2> A = makeNeumannLaplacian<2>(dims, {false, true}, 1.0 / 64);
  A.c.densify();
  for (size_t i = 0; i < A.size(); ++i) A.c.at(i) = 0.5f;
  A.finalize();
  Vector unit(A.size());
  for (size_t i = 0; i < unit.size(); ++i) unit[i] = std::sin(0.3 * double(i)) + 0.2 * std::cos(0.01 * double(i));
  Multigrid<2> mg(A);
  SolverOptions o{1e-9, 200};
  Vector x1(A.size(), 0.0);
  ASSERT_TRUE(solvePCG<2>(A, unit, &x1, &mg, o).converged);
  for (double scale : {1e-60, 1e60}) {
    Vector b(unit.size());
    for (size_t i = 0; i < b.size(); ++i) b[i] = scale * unit[i];
    Vector xp(A.size(), 0.0), xm(A.size(), 0.0);
    SolverResult rp = solvePCG<2>(A, b, &xp, &mg, o);
    SolverResult rm = mg.solve(b, &xm, o);
    ASSERT_TRUE(rp.converged && rm.converged) << scale << " " << rp.residual << " " << rm.residual;
    for (size_t i = 0; i < x1.size(); ++i) {
      EXPECT_NEAR(xp[i] / scale, x1[i], 1e-7 * std::abs(x1[i]) + 1e-9);
      EXPECT_NEAR(xm[i] / scale, x1[i], 1e-7 * std::abs(x1[i]) + 1e-9);
    }
  }
}

namespace {

// Calls fn(j, w) for each face neighbour j of cell k (index i) with the
// face's weight w, along each axis the upper then the lower one; periodic
// axes wrap, walls are skipped.
template <int D, class Fn>
void eachNeighbour(const LaplaceSystem<D>& A, const IVec<D>& k, size_t i, Fn&& fn) {
  for (int a = 0; a < D; ++a) {
    IVec<D> lo = k, hi = k;
    lo[a] -= 1;
    hi[a] += 1;
    if (A.periodic[size_t(a)]) {
      lo[a] = (lo[a] + A.dims[a]) % A.dims[a];
      hi[a] %= A.dims[a];
    }
    if (hi[a] < A.dims[a]) fn(A.c.index(hi), double(A.w[a][i]));
    if (lo[a] >= 0) fn(A.c.index(lo), double(A.w[a][A.c.index(lo)]));
  }
}

// A system whose rows break into several uniform spans (a partial face and
// a heavier diagonal inside some rows), faces of weight `weight`, walls on
// the upper sides (the last axis periodic if asked): the fast paths' test bed.
template <int D>
LaplaceSystem<D> brokenSpanSystem(const IVec<D>& dims, float weight, bool periodicLast) {
  std::array<bool, D> periodic{};
  periodic[D - 1] = periodicLast;
  LaplaceSystem<D> A(dims, periodic, 3.0);
  for (int a = 0; a < D; ++a) A.w[a].fill(weight);
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    A.c.at(i) = 0.5f;
    for (int a = 0; a < D; ++a) {
      if (k[a] == dims[a] - 1 && !periodic[size_t(a)]) A.w[a].at(i) = 0.0f;  // walls
      if (k[0] == 9 && k[1] % 3 == 0) A.w[a].at(i) = 0.5f * weight;
      if (k[0] == 17 && k[1] % 4 == 1) A.c.at(i) = 2.0f;
    }
  });
  A.finalize();
  return A;
}

// One red-black Gauss-Seidel sweep written plainly (double arithmetic, every
// neighbour through its weight, walls by skipping): the reference for the
// smoother's fast paths (uniform spans four cells at a time in float). With
// `only`, the cells it flags alone are updated.
template <int D>
std::vector<double> referenceSweep(const LaplaceSystem<D>& A, const std::vector<float>& b, std::vector<float> x,
                                   bool reverse, const std::vector<uint8_t>* only = nullptr) {
  std::vector<double> xd(x.begin(), x.end());
  for (int pass = 0; pass < 2; ++pass) {
    const int colour = reverse ? 1 - pass : pass;
    for (size_t i = 0; i < A.size(); ++i) {
      const IVec<D> k = A.c.coord(i);
      int parity = 0;
      for (int a = 0; a < D; ++a) parity += k[a];
      if ((parity & 1) != colour || !(A.diag[i] > 0) || (only && !(*only)[i])) continue;
      double sum = 0.0;
      eachNeighbour<D>(A, k, i, [&](size_t j, double w) { sum += w * xd[j]; });
      xd[i] = (double(b[i]) / A.scale + sum) / double(A.diag[i]);
    }
  }
  return xd;
}

template <int D>
void checkSmoother(const IVec<D>& dims, float weight = 1.0f, bool periodicLast = false) {
  const LaplaceSystem<D> A = brokenSpanSystem<D>(dims, weight, periodicLast);
  std::vector<float> b(A.size()), x(A.size());
  for (size_t i = 0; i < b.size(); ++i) {
    b[i] = float(std::sin(0.37 * double(i)));
    x[i] = float(std::cos(0.11 * double(i)));
  }
  const bool wide = useAvx2();
  for (bool reverse : {false, true}) {
    const std::vector<double> ref = referenceSweep<D>(A, b, x, reverse);
    std::vector<float> y = x;
    A.gaussSeidel(b, &y, reverse);
    double worst = 0.0, scale = 0.0;
    for (size_t i = 0; i < y.size(); ++i) {
      worst = std::max(worst, std::abs(double(y[i]) - ref[i]));
      scale = std::max(scale, std::abs(ref[i]));
    }
    EXPECT_LT(worst, 1e-5 * scale) << "dims " << dims[0] << "x" << dims[1] << " reverse " << reverse;
    // The four-lane kernels give bitwise the same sweep as the eight-lane
    // ones (where the CPU has AVX2; otherwise both runs take four lanes).
    setUseAvx2(false);
    std::vector<float> narrow = x;
    A.gaussSeidel(b, &narrow, reverse);
    setUseAvx2(wide);
    EXPECT_EQ(0, std::memcmp(y.data(), narrow.data(), y.size() * sizeof(float)))
        << "dims " << dims[0] << "x" << dims[1] << " reverse " << reverse;
  }
}

// A x written plainly in double (every face through its weight, walls by
// skipping): the reference for the operator's fast paths.
template <int D>
std::vector<double> referenceApply(const LaplaceSystem<D>& A, const std::vector<double>& x) {
  std::vector<double> y(A.size(), 0.0);
  for (size_t i = 0; i < A.size(); ++i) {
    const IVec<D> k = A.c.coord(i);
    double sum = double(A.c[i]) * x[i];
    eachNeighbour<D>(A, k, i, [&](size_t j, double w) { sum += w * (x[i] - x[j]); });
    y[i] = A.scale * sum;
  }
  return y;
}

template <int D>
void checkOperator(const IVec<D>& dims, float weight = 1.0f, bool periodicLast = false) {
  const LaplaceSystem<D> A = brokenSpanSystem<D>(dims, weight, periodicLast);
  Vector x(A.size()), b(A.size());
  for (size_t i = 0; i < x.size(); ++i) {
    x[i] = std::cos(0.11 * double(i)) + 0.3 * std::sin(0.013 * double(i));
    b[i] = std::sin(0.37 * double(i));
  }
  const std::vector<double> ref = referenceApply<D>(A, x);
  double scale = 0.0;
  for (double v : ref) scale = std::max(scale, std::abs(v));
  const std::string where = "dims " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]);
  const bool wide = useAvx2();
  for (bool narrow : {false, true}) {
    if (narrow) setUseAvx2(false);
    Vector y, r;
    y.resize(A.size());
    r.resize(A.size());
    const double xy = A.applyDot(x, &y);
    const double rnorm = A.residual(b, x, &r);
    std::vector<float> xf(x.begin(), x.end()), bf(b.begin(), b.end()), yf(A.size()), rf(A.size());
    A.apply(xf, &yf);
    A.defect(bf, xf, &rf);
    setUseAvx2(wide);
    double refXY = 0.0, refRR = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      EXPECT_NEAR(y[i], ref[i], 1e-12 * scale) << where << " cell " << i;
      EXPECT_NEAR(r[i], b[i] - ref[i], 1e-12 * scale) << where << " cell " << i;
      EXPECT_NEAR(yf[i], ref[i], 1e-5 * scale) << where << " cell " << i;
      EXPECT_NEAR(rf[i], b[i] - ref[i], 1e-5 * scale) << where << " cell " << i;
      refXY += x[i] * ref[i];
      refRR += (b[i] - ref[i]) * (b[i] - ref[i]);
    }
    EXPECT_NEAR(xy, refXY, 1e-12 * std::abs(refXY) + 1e-12) << where;
    EXPECT_NEAR(rnorm, std::sqrt(refRR), 1e-12 * std::sqrt(refRR)) << where;
    if (!narrow) continue;
    // The 256-bit kernels give bitwise the results of the narrow ones.
    Vector yw(A.size()), rw(A.size());
    std::vector<float> yfw(A.size()), rfw(A.size());
    const double xyw = A.applyDot(x, &yw), rnormw = A.residual(b, x, &rw);
    A.apply(xf, &yfw);
    A.defect(bf, xf, &rfw);
    EXPECT_EQ(xy, xyw) << where;
    EXPECT_EQ(rnorm, rnormw) << where;
    EXPECT_EQ(0, std::memcmp(y.data(), yw.data(), y.size() * sizeof(double))) << where;
    EXPECT_EQ(0, std::memcmp(r.data(), rw.data(), r.size() * sizeof(double))) << where;
    EXPECT_EQ(0, std::memcmp(yf.data(), yfw.data(), yf.size() * sizeof(float))) << where;
    EXPECT_EQ(0, std::memcmp(rf.data(), rfw.data(), rf.size() * sizeof(float))) << where;
  }
}

}  // namespace

// A x, x . A x, b - A x and ||b - A x|| through the fast paths (uniform
// spans, 256-bit where the CPU has AVX2) against the plain stencil, with
// spans broken by partial faces and other diagonals, walls, periodic axes,
// faces that all weigh 0.3 (the RD diffusion systems').
TEST(LinearSolvers, OperatorMatchesThePlainStencil) {
  checkOperator<2>(IVec<2>(37, 12));
  checkOperator<2>(IVec<2>(64, 9), 0.3f);
  checkOperator<3>(IVec<3>(29, 10, 7));
  checkOperator<3>(IVec<3>(71, 6, 5), 0.3f);
  checkOperator<3>(IVec<3>(64, 16, 40), 1.0f, true);
}

// The smoother's float fast paths (uniform spans, four or eight cells at a time) give
// a red-black Gauss-Seidel sweep: odd and even rows, spans broken by partial
// faces and other diagonals, walls, 2D and 3D.
TEST(LinearSolvers, SmootherMatchesAPlainRedBlackSweep) {
  checkSmoother<2>(IVec<2>(37, 12));
  checkSmoother<2>(IVec<2>(64, 9));
  checkSmoother<2>(IVec<2>(23, 23));
  checkSmoother<3>(IVec<3>(29, 10, 7));
  checkSmoother<3>(IVec<3>(71, 6, 5));  // spans long enough for the eight-lane kernel
  // Faces that all weigh 0.3, as the RD diffusion systems' do.
  checkSmoother<2>(IVec<2>(64, 9), 0.3f);
  checkSmoother<3>(IVec<3>(71, 6, 5), 0.3f);
  // Large enough to be cut into slabs (two or more, each with first and
  // last planes another slab reads), walled and periodic along the cut.
  checkSmoother<2>(IVec<2>(64, 600));
  checkSmoother<3>(IVec<3>(64, 16, 40));
  checkSmoother<3>(IVec<3>(64, 16, 40), 0.3f, true);
}

namespace {

// A body cut from a Neumann box: a ball of radius 0.3 n_y about the
// centre (periodic along x when asked, the ball then across the seam),
// each face open by its centre's distance outside it (clamped to [0, 1]),
// as cut cells give.
template <int D>
LaplaceSystem<D> cutBallSystem(const IVec<D>& dims, bool periodicX) {
  std::array<bool, D> periodic{};
  periodic[0] = periodicX;
  LaplaceSystem<D> A(dims, periodic, 1.0);
  for (int a = 0; a < D; ++a) A.w[a].fill(1.0f);
  const double radius = 0.3 * dims[1];
  auto open = [&](const IVec<D>& k, int a) {
    double d2 = 0.0;
    for (int b = 0; b < D; ++b) {
      double x = k[b] + (b == a ? 1.0 : 0.5) - 0.5 * dims[b];
      if (b == 0 && periodicX) x = std::remainder(x + 0.5 * dims[0], double(dims[0]));
      d2 += x * x;
    }
    return float(std::clamp(std::sqrt(d2) - radius + 0.5, 0.0, 1.0));
  };
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    for (int a = 0; a < D; ++a) A.w[a].at(i) = open(k, a);
  });
  A.finalize();
  return A;
}

// The band by its definition, plainly: the active cells either side of a
// face inside the domain that weighs less than 1, grown `width` times by
// the active face neighbours.
template <int D>
std::vector<uint8_t> referenceBand(const LaplaceSystem<D>& A, int width) {
  std::vector<uint8_t> in(A.size(), 0);
  for (size_t i = 0; i < A.size(); ++i) {
    const IVec<D> k = A.c.coord(i);
    for (int a = 0; a < D; ++a) {
      IVec<D> up = k;
      up[a] += 1;
      if (A.periodic[size_t(a)]) up[a] %= A.dims[a];
      if (up[a] >= A.dims[a] || !(A.w[a][i] < 1.0f)) continue;
      for (size_t c : {i, A.c.index(up)}) in[c] = A.diag[c] > 0;
    }
  }
  for (int step = 0; step < width; ++step) {
    std::vector<uint8_t> grown = in;
    for (size_t i = 0; i < A.size(); ++i)
      if (in[i]) eachNeighbour<D>(A, A.c.coord(i), i, [&](size_t j, double) { grown[j] = A.diag[j] > 0; });
    in.swap(grown);
  }
  return in;
}

template <int D>
void expectBandMatches(const LaplaceSystem<D>& A) {
  for (int width : {0, 1, 2}) {
    const BoundaryBand<D> band = boundaryBand<D>(A, width);
    const std::vector<uint8_t> ref = referenceBand<D>(A, width);
    std::vector<uint8_t> got(A.size(), 0);
    for (int colour = 0; colour < 2; ++colour) {
      const std::vector<uint32_t>& cells = band.colour[size_t(colour)];
      EXPECT_TRUE(std::is_sorted(cells.begin(), cells.end()));
      for (uint32_t i : cells) {
        const IVec<D> k = A.c.coord(i);
        int parity = 0;
        for (int a = 0; a < D; ++a) parity += k[a];
        EXPECT_EQ(parity & 1, colour);
        EXPECT_EQ(got[i], 0) << "twice: " << i;
        got[i] = 1;
      }
    }
    EXPECT_EQ(got, ref) << "width " << width;
    EXPECT_GT(band.size(), 0u);
    EXPECT_LT(band.size(), A.size() / 2);
  }
}

template <int D>
void expectBandIsItsDefinition(const IVec<D>& dims, bool periodicX) {
  expectBandMatches<D>(cutBallSystem<D>(dims, periodicX));
}

// One band sweep: the plain red-black sweep on the band's cells (as the
// smoother's reference computes it), every other cell bit for bit as it was.
template <int D>
void expectBandSweepIsARedBlackSweepOnItsCells(const IVec<D>& dims, bool periodicX) {
  const LaplaceSystem<D> A = cutBallSystem<D>(dims, periodicX);
  const BoundaryBand<D> band = boundaryBand<D>(A, 1);
  std::vector<uint8_t> in(A.size(), 0);
  for (const auto& cells : band.colour)
    for (uint32_t i : cells) in[i] = 1;
  std::vector<float> b(A.size()), x(A.size());
  for (size_t i = 0; i < b.size(); ++i) {
    b[i] = float(std::sin(0.37 * double(i)));
    x[i] = A.diag[i] > 0 ? float(std::cos(0.11 * double(i))) : 0.0f;
  }
  for (bool reverse : {false, true}) {
    std::vector<float> y = x;
    sweepBand<D, float>(A, band, b.data(), y.data(), reverse);
    // The reference sweep on the band's cells, and everywhere.
    const std::vector<double> xd = referenceSweep<D>(A, b, x, reverse, &in);
    const std::vector<double> ref = referenceSweep<D>(A, b, x, reverse);
    double worst = 0.0, scale = 0.0;
    size_t moved = 0;
    for (size_t i = 0; i < A.size(); ++i) {
      if (!in[i]) {
        EXPECT_EQ(std::memcmp(&y[i], &x[i], sizeof(float)), 0) << "outside the band: " << i;
        continue;
      }
      worst = std::max(worst, std::abs(double(y[i]) - xd[i]));
      scale = std::max(scale, std::abs(xd[i]));
      moved += xd[i] != double(x[i]);
      // A band cell whose neighbours all lie in the band takes the whole sweep's value.
      bool inner = true;
      eachNeighbour<D>(A, A.c.coord(i), i, [&](size_t j, double) { inner = inner && (in[j] || !(A.diag[j] > 0)); });
      if (inner) {
        EXPECT_NEAR(xd[i], ref[i], 1e-12 * (1.0 + std::abs(ref[i])));
      }
    }
    EXPECT_LT(worst, 1e-5 * scale) << "reverse " << reverse;
    EXPECT_GT(moved, band.size() / 2);
  }
}

}  // namespace

// The band of a cut ball: the active cells beside its partial and closed
// faces, grown face by face (0, 1, 2), as found cell by cell; across a
// periodic seam too.
TEST(BoundaryBand, IsTheActiveCellsBesideCutFacesGrownFaceByFace) {
  // One partial face, across the periodic seam: its two cells, then their neighbours.
  LaplaceSystem<2> seam = makeNeumannLaplacian<2>(IVec<2>(8, 6), {true, false}, 1.0);
  seam.w[0].densify();
  seam.w[0].at(seam.c.index(IVec<2>(7, 3))) = 0.5f;
  seam.finalize();
  const BoundaryBand<2> two = boundaryBand<2>(seam, 0);
  EXPECT_EQ(two.colour[0], std::vector<uint32_t>{uint32_t(seam.c.index(IVec<2>(7, 3)))});
  EXPECT_EQ(two.colour[1], std::vector<uint32_t>{uint32_t(seam.c.index(IVec<2>(0, 3)))});
  EXPECT_EQ(boundaryBand<2>(seam, 1).size(), 2u + 6u);
  expectBandMatches<2>(seam);
  expectBandIsItsDefinition<2>(IVec<2>(40, 30), false);
  expectBandIsItsDefinition<2>(IVec<2>(30, 30), true);
  expectBandIsItsDefinition<3>(IVec<3>(20, 16, 12), false);
  expectBandIsItsDefinition<3>(IVec<3>(16, 16, 12), true);
}

TEST(BoundaryBand, SweepIsARedBlackSweepOnItsCells) {
  expectBandSweepIsARedBlackSweepOnItsCells<2>(IVec<2>(40, 30), false);
  expectBandSweepIsARedBlackSweepOnItsCells<3>(IVec<3>(20, 16, 12), true);
}

// With boundary smoothing the V-cycle stays a symmetric operator (PCG
// needs one): the band's sweeps after the pre-smoothing, their adjoints
// before the post-smoothing.
TEST(BoundaryBand, TheCycleStaysSymmetric) {
  for (bool periodicX : {false, true}) {
    const LaplaceSystem<3> A = cutBallSystem<3>(IVec<3>(32, 24, 20), periodicX);
    MultigridOptions o;
    o.bandSweeps = 4;
    o.bandMinCells = 0;  // every level but the coarsest
    Multigrid<3> mg(A, o);
    ASSERT_FALSE(mg.band(0).empty());
    ASSERT_FALSE(mg.band(1).empty());
    EXPECT_TRUE(mg.band(mg.levels() - 1).empty());
    Vector a(A.size()), b(A.size()), ma, mb;
    for (size_t i = 0; i < a.size(); ++i) {
      a[i] = A.diag[i] > 0 ? std::sin(1.3 * double(i)) : 0.0;
      b[i] = A.diag[i] > 0 ? std::cos(0.7 * double(i) + 0.2) : 0.0;
    }
    mg.apply(a, &ma);
    mg.apply(b, &mb);
    const double ab = dot(ma, b), ba = dot(a, mb);
    EXPECT_NEAR(ab, ba, 1e-5 * std::abs(ab));
    Multigrid<3> plain(A);
    Vector pa;
    plain.apply(a, &pa);
    EXPECT_NE(pa, ma);  // (the band's sweeps do something)
  }
}
