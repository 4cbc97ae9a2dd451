// The Chebyshev iteration on systems with an identity term (implicit
// viscosity's A = s (1/s + boundary terms + L), L >= 0): its residual after
// k steps obeys the Chebyshev bound, it solves manufactured systems to the
// error the residual allows (A >= I, so ||x - x*|| <= ||r||), and its
// blocked, sliced and vectorised layouts all give bitwise the plain sweeps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "core/chebyshev.h"
#include "core/parallel.h"
#include "core/simd_dispatch.h"

using namespace morphoflow;

namespace {

// The viscous system on a box: c = 1/s (+ 2 per wall face, a mirrored
// ghost; + 1 per face on the obstacle, a prescribed neighbour), w = 1 but
// partial faces (0.5) on some rows, a cube of inactive cells (the
// obstacle), the last axis periodic if asked.
template <int D>
LaplaceSystem<D> viscousSystem(const IVec<D>& dims, double s, bool periodicLast) {
  std::array<bool, D> periodic{};
  periodic[D - 1] = periodicLast;
  LaplaceSystem<D> A(dims, periodic, s);
  for (int a = 0; a < D; ++a) A.w[a].fill(1.0f);
  auto solid = [&](const IVec<D>& k) {
    bool in = true;
    for (int a = 0; a < D; ++a) in &= k[a] >= 4 && k[a] < 7;
    return in;
  };
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    if (solid(k)) return;
    float c = float(1.0 / s);
    for (int a = 0; a < D; ++a) {
      if (!periodic[size_t(a)]) c += (k[a] == 0 ? 2.0f : 0.0f) + (k[a] == dims[a] - 1 ? 2.0f : 0.0f);
      if (k[0] == 9 && k[1] % 3 == 0) A.w[a].at(i) = 0.5f;
      for (int dir = -1; dir <= 1; dir += 2) {
        IVec<D> nb = k;
        nb[a] += dir;
        if (periodic[size_t(a)]) nb[a] = (nb[a] + dims[a]) % dims[a];
        if (nb[a] < 0 || nb[a] >= dims[a] || !solid(nb)) continue;
        c += 1.0f;
        A.w[a].at(dir > 0 ? i : A.c.index(nb)) = 0.0f;
      }
    }
    A.c.at(i) = c;
  });
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    if (!solid(k)) return;
    for (int a = 0; a < D; ++a) A.w[a].at(i) = 0.0f;
  });
  A.finalize();
  return A;
}

template <int D>
Vector wavyVector(const LaplaceSystem<D>& A, double phase) {
  Vector v(A.size());
  for (size_t i = 0; i < v.size(); ++i)
    v[i] = A.diag[i] > 0 ? std::sin(0.37 * double(i) + phase) + 0.5 * std::cos(0.013 * double(i)) : 0.0;
  return v;
}

template <int D>
std::string name(const IVec<D>& dims) {
  std::string n;
  for (int a = 0; a < D; ++a) n += (a ? "x" : "") + std::to_string(dims[a]);
  return n;
}

// rho, the Gershgorin radius of D^-1 W, and the active diagonals' spread,
// from their definitions.
template <int D>
void spectrumBounds(const LaplaceSystem<D>& A, double* rho, double* diagRatio) {
  double r = 0.0, dmin = 1e300, dmax = 0.0;
  forEachCell<D>(A.dims, [&](const IVec<D>& k, size_t i) {
    const double d = A.diag[i];
    if (!(d > 0)) return;
    double sum = 0.0;
    for (int a = 0; a < D; ++a) {
      IVec<D> lo = k;
      lo[a] -= 1;
      if (A.periodic[size_t(a)]) lo[a] = (lo[a] + A.dims[a]) % A.dims[a];
      sum += A.w[a][i] + (lo[a] >= 0 ? A.w[a][A.c.index(lo)] : 0.0f);
    }
    r = std::max(r, sum / d);
    dmin = std::min(dmin, d);
    dmax = std::max(dmax, d);
  });
  *rho = r;
  *diagRatio = dmax / dmin;
}

template <int D>
void checkChebyshevBound(const IVec<D>& dims, double s, bool periodicLast) {
  const LaplaceSystem<D> A = viscousSystem<D>(dims, s, periodicLast);
  double rho, diagRatio;
  spectrumBounds<D>(A, &rho, &diagRatio);
  ChebyshevLayout full;
  full.cyclic = false;
  Chebyshev<D> cheb(A, full);
  ASSERT_TRUE(cheb.applicable());
  EXPECT_GE(cheb.rho(), rho);
  EXPECT_LE(cheb.rho(), rho * (1.0 + 1e-4));
  const Vector b = wavyVector<D>(A, 0.0);
  // After k steps from 0: ||r_k|| <= sqrt(max d / min d) ||b|| / T_k(1 / rho).
  auto bound = [&](int k) { return std::sqrt(diagRatio) / std::cosh(k * std::acosh(1.0 / cheb.rho())); };
  for (int k : {1, 2, 3, 5, 8, 13}) {
    Vector x(A.size(), 0.0);
    const SolverResult r = cheb.solve(b, &x, SolverOptions{1e-14, k});
    EXPECT_EQ(r.iterations, k);
    EXPECT_LE(r.residual, bound(k) * (1.0 + 1e-4) + 1e-6) << name<D>(dims) << " k = " << k;
  }
  // The step count asked for a reduction is the least the bound allows.
  for (double factor : {10.0, 1e3, 1e4}) {
    const int k = cheb.stepsFor(factor);
    EXPECT_LE(bound(k), 1.0 / factor * (1.0 + 1e-9));
    if (k > 1) {
      EXPECT_GT(bound(k - 1), 1.0 / factor);
    }
  }
}

}  // namespace

// (The full iteration's: the cyclic one's round ends otherwise; see
// CyclicStepsAreTheFullIterationsOwn.)
TEST(Chebyshev, ResidualObeysTheChebyshevBound) {
  checkChebyshevBound<2>(IVec<2>(40, 33), 1.28, false);
  checkChebyshevBound<2>(IVec<2>(40, 33), 12.0, true);
  checkChebyshevBound<3>(IVec<3>(19, 14, 23), 1.28, false);
  checkChebyshevBound<3>(IVec<3>(19, 14, 23), 0.2, true);
}

namespace {

// b = A x* for a known x*; A >= I (scale s times c >= 1/s), so the error is
// at most the residual: ||x - x*|| <= tol ||b||. A tolerance of 1e-10 takes
// several rounds of single-precision steps.
template <int D>
void checkManufactured(const IVec<D>& dims, double s, bool periodicLast) {
  const LaplaceSystem<D> A = viscousSystem<D>(dims, s, periodicLast);
  const Vector exact = wavyVector<D>(A, 0.4);
  Vector b(A.size());
  A.apply(exact, &b);
  Chebyshev<D> cheb(A);
  const double tol = 1e-10;
  Vector x(A.size(), 0.0);
  const SolverResult r = cheb.solve(b, &x, SolverOptions{tol, 2000});
  EXPECT_TRUE(r.converged) << name<D>(dims);
  EXPECT_LE(r.residual, tol * 1.0001);
  EXPECT_GT(r.iterations, cheb.stepsFor(1e4));  // beyond a single 1e4 reduction
  double err = 0.0, bb = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    err += (x[i] - exact[i]) * (x[i] - exact[i]);
    bb += b[i] * b[i];
    if (!(A.diag[i] > 0)) {
      ASSERT_EQ(x[i], 0.0) << "inactive cell " << i;
    }
  }
  EXPECT_LE(std::sqrt(err), tol * std::sqrt(bb)) << name<D>(dims);
}

}  // namespace

TEST(Chebyshev, SolvesManufacturedSystems) {
  checkManufactured<2>(IVec<2>(64, 50), 1.28, false);
  checkManufactured<2>(IVec<2>(37, 64), 20.0, true);
  checkManufactured<3>(IVec<3>(24, 20, 30), 1.28, false);
  checkManufactured<3>(IVec<3>(17, 12, 26), 3.0, true);
}

namespace {

template <int D>
void checkLayouts(const IVec<D>& dims, bool periodicLast, bool cyclic) {
  const LaplaceSystem<D> A = viscousSystem<D>(dims, 2.0, periodicLast);
  const Vector b = wavyVector<D>(A, 1.0);
  const SolverOptions fixed{1e-300, 23};  // 23 steps, whatever they reach
  Vector ref(A.size(), 0.0);
  {
    ThreadLimit one(1);
    Chebyshev<D>(A, ChebyshevLayout{1, 1, cyclic}).solve(b, &ref, fixed);  // plain sweeps, one task
  }
  const bool wide = useAvx2();
  for (ChebyshevLayout layout : {ChebyshevLayout{4, 0}, ChebyshevLayout{3, 5}, ChebyshevLayout{6, 2},
                                 ChebyshevLayout{2, 9}, ChebyshevLayout{8, 3}})
    for (bool narrow : {false, true}) {
      layout.cyclic = cyclic;
      if (narrow) setUseAvx2(false);
      Vector x(A.size(), 0.0);
      Chebyshev<D>(A, layout).solve(b, &x, fixed);
      setUseAvx2(wide);
      EXPECT_EQ(0, std::memcmp(x.data(), ref.data(), x.size() * sizeof(double)))
          << name<D>(dims) << " steps/pass " << layout.stepsPerPass << " slabs " << layout.slabs << " narrow " << narrow
          << " cyclic " << cyclic;
    }
}

}  // namespace

// Blocking in time (several steps per pass), cutting the planes into slabs
// (walled or periodic along the cut), thread count and vector width change
// nothing: every step of every plane reads the same values.
TEST(Chebyshev, LayoutDoesNotChangeTheResult) {
  for (bool cyclic : {true, false}) {
    checkLayouts<2>(IVec<2>(41, 90), false, cyclic);
    checkLayouts<2>(IVec<2>(41, 90), true, cyclic);
    checkLayouts<3>(IVec<3>(37, 9, 40), false, cyclic);
    checkLayouts<3>(IVec<3>(37, 9, 40), true, cyclic);
    checkLayouts<3>(IVec<3>(20, 8, 7), true, cyclic);  // too thin to cut: plain sweeps; odd and periodic: not cyclic
  }
}

namespace {

// The cyclic iteration's steps are the full iteration's own values: one
// round of k steps from x = 0 leaves x = e / rscale, and on the cells of
// colour k mod 2 (those whose e_k it computed) its x is the full
// iteration's, bit for bit. Its round then takes the other colour from
// them by a Jacobi half step, which zeroes that colour's residual: the
// residual is the reduced system's, on which the k steps are the optimal
// polynomial's, within a little of the full iteration's (at the spectrum's
// ends, where the full one's is exactly 1 / T_k(1 / rho), 1.2-1.25 of it).
template <int D>
void checkCyclic(const IVec<D>& dims, double s, bool periodicLast) {
  const LaplaceSystem<D> A = viscousSystem<D>(dims, s, periodicLast);
  const Vector b = wavyVector<D>(A, 0.7);
  ChebyshevLayout full;
  full.cyclic = false;
  Chebyshev<D> cyclic(A), plain(A, full);
  ASSERT_TRUE(cyclic.cyclic());
  ASSERT_FALSE(plain.cyclic());
  for (int k : {2, 3, 6, 11}) {
    Vector xc(A.size(), 0.0), xf(A.size(), 0.0);
    const SolverOptions steps{1e-300, k};
    const SolverResult rc = cyclic.solve(b, &xc, steps), rf = plain.solve(b, &xf, steps);
    size_t same = 0, compared = 0;
    forEachCell<D>(dims, [&](const IVec<D>& c, size_t i) {
      int parity = 0;
      for (int a = 0; a < D; ++a) parity += c[a];
      if (parity % 2 != k % 2) return;
      ++compared;
      same += xc[i] == xf[i];
    });
    EXPECT_EQ(same, compared) << name<D>(dims) << " k = " << k;
    EXPECT_LE(rc.residual, 1.3 * rf.residual) << name<D>(dims) << " k = " << k;
  }
}

}  // namespace

TEST(Chebyshev, CyclicStepsAreTheFullIterationsOwn) {
  checkCyclic<2>(IVec<2>(40, 33), 1.28, false);
  checkCyclic<2>(IVec<2>(41, 34), 12.0, true);
  checkCyclic<3>(IVec<3>(19, 14, 23), 1.28, false);
  checkCyclic<3>(IVec<3>(19, 14, 24), 0.2, true);
}

// A pure Laplacian (no identity term) has 0 in its spectrum: the iteration
// does not apply, and says so; any identity term makes it apply.
TEST(Chebyshev, AppliesOnlyWithAnIdentityTerm) {
  LaplaceSystem<2> A = makeNeumannLaplacian<2>(IVec<2>(16, 16), {}, 1.0 / 16);
  A.c.densify();
  EXPECT_FALSE(Chebyshev<2>(A).applicable());
  for (size_t i = 0; i < A.size(); ++i) A.c.at(i) = 1e-3f;
  A.finalize();
  Chebyshev<2> cheb(A);
  EXPECT_TRUE(cheb.applicable());
  EXPECT_LT(cheb.rho(), 1.0);
}

namespace {

// On a periodic box of one uniform stencil, the constant vector and the
// checkerboard are eigenvectors of D^-1 A at the interval's ends, 1 -+ rho,
// where the residual polynomial peaks: from x = 0, the residual of b = their
// sum after k steps is exactly 1 / T_k(1 / rho) of b's.
template <int D>
void checkExtremalModes(const IVec<D>& dims, double s) {
  std::array<bool, D> periodic;
  periodic.fill(true);
  LaplaceSystem<D> A(dims, periodic, s);
  for (int a = 0; a < D; ++a) A.w[a].fill(1.0f);
  A.c.fill(float(1.0 / s));
  A.finalize();
  ChebyshevLayout full;
  full.cyclic = false;
  Chebyshev<D> cheb(A, full), cyclic(A);
  const double rho = 2.0 * D / (double(float(1.0 / s)) + 2.0 * D);  // sum w / diag, diag = c + sum w
  EXPECT_NEAR(cheb.rho(), rho, 2e-5 * rho);
  Vector b(A.size());
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    int parity = 0;
    for (int a = 0; a < D; ++a) parity += k[a];
    b[i] = 1.0 + (parity % 2 ? -0.5 : 0.5);
  });
  for (int k : {1, 2, 3, 4, 7, 12}) {
    Vector x(A.size(), 0.0);
    const SolverResult r = cheb.solve(b, &x, SolverOptions{1e-14, k});
    const double exact = 1.0 / std::cosh(k * std::acosh(1.0 / cheb.rho()));
    EXPECT_NEAR(r.residual, exact, 2e-3 * exact + 1e-6) << name<D>(dims) << " k = " << k;
    Vector xc(A.size(), 0.0);  // the cyclic iteration: a little above it (CyclicStepsAreTheFullIterationsOwn)
    const SolverResult rc = cyclic.solve(b, &xc, SolverOptions{1e-14, k});
    EXPECT_GE(rc.residual, exact * (1.0 - 2e-3)) << name<D>(dims) << " k = " << k;
    EXPECT_LE(rc.residual, 1.3 * exact) << name<D>(dims) << " k = " << k;
  }
}

}  // namespace

// Refreshed after its system's coefficients changed (another rate, another
// obstacle's rows), the iteration is bitwise one built on the new system:
// its bounds and its coefficients outside the uniform spans, found once per
// kind of row, are every row's own.
template <int D>
void checkRefresh(const IVec<D>& dims, bool periodicLast) {
  LaplaceSystem<D> A = viscousSystem<D>(dims, 1.28, periodicLast);
  Chebyshev<D> kept(A);
  const SolverOptions fixed{1e-300, 17};
  for (double s : {4.0, 0.3}) {
    A = viscousSystem<D>(dims, s, periodicLast);
    A.w[D - 1].densify();
    forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {  // partial faces: rows alike but for the faces below
      if (k[D - 1] == 2 && k[0] % 5 == 1 && k[0] > 10) A.w[D - 1].at(i) = float(0.25 * s);
    });
    A.finalize();
    kept.refresh();
    Chebyshev<D> fresh(A);
    EXPECT_EQ(kept.rho(), fresh.rho()) << name<D>(dims) << " s = " << s;
    const Vector b = wavyVector<D>(A, 0.9);
    Vector x1(A.size(), 0.0), x2(A.size(), 0.0);
    kept.solve(b, &x1, fixed);
    fresh.solve(b, &x2, fixed);
    EXPECT_EQ(0, std::memcmp(x1.data(), x2.data(), x1.size() * sizeof(double))) << name<D>(dims) << " s = " << s;
  }
}

TEST(Chebyshev, RefreshIsAFreshIteration) {
  checkRefresh<2>(IVec<2>(40, 33), false);
  checkRefresh<2>(IVec<2>(40, 34), true);
  checkRefresh<3>(IVec<3>(19, 14, 23), false);
  checkRefresh<3>(IVec<3>(19, 14, 22), true);
}

TEST(Chebyshev, ResidualIsTheChebyshevPolynomialAtTheSpectrumsEnds) {
  checkExtremalModes<2>(IVec<2>(32, 24), 1.28);
  checkExtremalModes<2>(IVec<2>(16, 40), 8.0);
  checkExtremalModes<3>(IVec<3>(16, 12, 30), 1.28);
}

// The steps run in single precision on a scaled correction: right-hand
// sides far outside float's range (1e-150, 1e+150: a decaying or exploding
// species) solve to scale, as those of order 1 do.
TEST(Chebyshev, SolvesAnyScale) {
  const LaplaceSystem<2> A = viscousSystem<2>(IVec<2>(40, 36), 2.0, false);
  const Vector unit = wavyVector<2>(A, 0.2);
  const SolverOptions o{1e-9, 2000};
  Vector x1(A.size(), 0.0);
  ASSERT_TRUE(Chebyshev<2>(A).solve(unit, &x1, o).converged);
  for (double scale : {1e-150, 1e150}) {
    Vector b(unit.size()), x(A.size(), 0.0);
    for (size_t i = 0; i < b.size(); ++i) b[i] = scale * unit[i];
    const SolverResult r = Chebyshev<2>(A).solve(b, &x, o);
    ASSERT_TRUE(r.converged) << scale << " " << r.residual;
    for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i] / scale, x1[i], 1e-7 * std::abs(x1[i]) + 1e-9) << scale;
  }
}

namespace {

// relaxBox on a solution spoilt in a box: the cells outside it keep their
// bits, the box's residual falls (red-black sweeps of a diagonally dominant
// system), and the result is bitwise the same on one thread and two.
template <int D>
void checkRelaxBox(const IVec<D>& dims, const IVec<D>& lo, const IVec<D>& hi, bool periodicLast) {
  const LaplaceSystem<D> A = viscousSystem<D>(dims, 2.0, periodicLast);
  const Vector b = wavyVector<D>(A, 0.3);
  Vector solved(A.size(), 0.0);
  ASSERT_TRUE(Chebyshev<D>(A).solve(b, &solved, SolverOptions{1e-12, 500}).converged);
  auto inBox = [&](const IVec<D>& k) {
    bool in = true;
    for (int a = 0; a < D; ++a) in &= k[a] >= lo[a] && k[a] < hi[a];
    return in;
  };
  Vector spoilt = solved;
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    if (inBox(k) && A.diag[i] > 0) spoilt[i] += 0.5 * std::sin(1.7 * double(i));
  });
  auto boxResidual = [&](const Vector& x) {
    Vector r(A.size());
    A.residual(b, x, &r);
    double sum = 0.0;
    forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) { sum += inBox(k) ? r[i] * r[i] : 0.0; });
    return std::sqrt(sum);
  };
  Vector one = spoilt, two = spoilt;
  {
    ThreadLimit limit(1);
    A.relaxBox(b, &one, lo, hi, 2);
  }
  {
    ThreadLimit limit(2);
    A.relaxBox(b, &two, lo, hi, 2);
  }
  EXPECT_EQ(0, std::memcmp(one.data(), two.data(), one.size() * sizeof(double))) << name<D>(dims);
  size_t moved = 0, outside = 0;
  forEachCell<D>(dims, [&](const IVec<D>& k, size_t i) {
    if (inBox(k)) moved += one[i] != spoilt[i] ? 1 : 0;
    else outside += std::memcmp(&one[i], &spoilt[i], sizeof(double)) != 0 ? 1 : 0;
  });
  EXPECT_EQ(outside, 0u) << name<D>(dims);
  EXPECT_GT(moved, 10u) << name<D>(dims);
  EXPECT_LT(boxResidual(one), 0.2 * boxResidual(spoilt)) << name<D>(dims);
}

}  // namespace

// The sweeps that mend a warm start on the rows a moving obstacle rewrote
// (fluid/viscosity.cpp) touch those rows alone, lower their residual and do
// not depend on the thread count, across a periodic axis too.
TEST(LaplaceSystem, RelaxBoxMendsTheBoxAlone) {
  checkRelaxBox<2>({24, 20}, {3, 5}, {15, 20}, true);
  checkRelaxBox<3>({14, 12, 10}, {2, 3, 0}, {11, 9, 10}, true);
  checkRelaxBox<3>({14, 12, 10}, {0, 0, 2}, {14, 7, 6}, false);
}
