// The implicit viscous step (I - nu dt lap) u = u* (Stam 1999) is one linear
// system for the whole MAC velocity, solved to a relative residual of that
// system. Scaled as the solver builds it, A = I + s (L + wall terms) with
// s = nu dt / h^2 and L >= 0 symmetric, so ||A^-1|| <= 1 and the error of
// the whole field is at most the residual:
//   ||u - u_exact|| <= ||r|| <= tol ||b||,  b = u* + s (wall terms),
// where the moving lid adds 2 s u_lid on the faces next to it.
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/viscosity.h"

namespace morphoflow {
namespace {

struct ViscousCase {
  int n = 48;
  double s = 1.28;       // nu dt / h^2: Chebyshev up to about 30 (2D) or 20 (3D), multigrid-preconditioned CG above
  double crossScale = 1e-4;  // the cross-flow component's size against the main flow
};

// A lid-driven box (lid along x on the high y side) whose x velocity is O(1)
// and whose y velocity is `crossScale` smaller: the cross-flow of a lid
// that has just started.
template <int D>
MacVelocity<D> startingFlow(const VelocityConstraints<D>& vc, double crossScale) {
  MacVelocity<D> u(vc.cells, vc.h, vc.periodic());
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = u[a];
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      double x = (k[0] + 0.5) * vc.h, y = (k[1] + 0.5) * vc.h;
      double v = std::sin(3.0 * x + 1.0) * std::cos(2.0 * y) + 0.5 * y * y;
      g[i] = float(a == 0 ? v : crossScale * std::cos(5.0 * x) * std::sin(4.0 * y + 0.3));
    });
  }
  vc.apply(&u);
  return u;
}

template <int D>
double fieldNorm(const MacVelocity<D>& u) {
  double s = 0.0;
  for (int a = 0; a < D; ++a)
    for (float v : u[a].values()) s += double(v) * double(v);
  return std::sqrt(s);
}

template <int D>
double fieldDistance(const MacVelocity<D>& u, const MacVelocity<D>& w) {
  double s = 0.0;
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      double d = double(u[a][i]) - double(w[a][i]);
      s += d * d;
    }
  return std::sqrt(s);
}

template <int D>
void checkWholeSystemTolerance(const ViscousCase& c) {
  DomainBoundaries b;  // walls on every side
  b.sides[3].wallVelocity = {1.0, 0.0, 0.0};
  const IVec<D> cells(c.n);
  const double h = 1.0 / c.n, nu = 0.01, dt = c.s * h * h / nu;
  VelocityConstraints<D> vc(cells, h, b, Grid<uint8_t, D>(cells, 0));
  const MacVelocity<D> start = startingFlow<D>(vc, c.crossScale);
  const double tol = 1e-6;

  MacVelocity<D> exact = start;
  ViscositySolver<D> tight(vc, SolverOptions{1e-13, 2000});
  ASSERT_TRUE(tight.diffuse(&exact, nu, dt).converged);

  MacVelocity<D> u = start;
  ViscositySolver<D> solver(vc, SolverOptions{tol, 500});
  const SolverResult r = solver.diffuse(&u, nu, dt);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.residual, tol * 1.0001);
  EXPECT_GT(r.iterations, 0);

  // ||b|| <= ||u*|| + s ||2 u_lid on the lid's neighbouring x faces||; the
  // bound above, plus both float velocities' rounding (half an ulp per value each).
  size_t lidFaces = size_t(c.n - 1);  // interior x faces along the lid
  for (int a = 2; a < D; ++a) lidFaces *= size_t(c.n);
  const double bNorm = fieldNorm(start) + c.s * 2.0 * std::sqrt(double(lidFaces));
  const double bound = tol * bNorm + 1.2e-7 * fieldNorm(exact);
  const double err = fieldDistance(u, exact);
  EXPECT_LE(err, bound) << "s = " << c.s;

  // The bound discriminates: one iteration is far from it, and says so.
  MacVelocity<D> rough = start;
  ViscositySolver<D> once(vc, SolverOptions{tol, 1});
  const SolverResult r1 = once.diffuse(&rough, nu, dt);
  EXPECT_FALSE(r1.converged);
  EXPECT_GT(r1.residual, tol);
  EXPECT_GT(fieldDistance(rough, exact), bound);
}

TEST(Viscosity, MeetsItsToleranceAsOneSystem2DChebyshev) { checkWholeSystemTolerance<2>({48, 1.28, 1e-4}); }
TEST(Viscosity, MeetsItsToleranceAsOneSystem2DSmallStep) { checkWholeSystemTolerance<2>({48, 0.05, 1e-4}); }
TEST(Viscosity, MeetsItsToleranceAsOneSystem2DMultigrid) { checkWholeSystemTolerance<2>({48, 60.0, 1e-4}); }
TEST(Viscosity, MeetsItsToleranceAsOneSystem3DChebyshev) { checkWholeSystemTolerance<3>({20, 1.28, 1e-4}); }
TEST(Viscosity, MeetsItsToleranceAsOneSystem3DMultigrid) { checkWholeSystemTolerance<3>({20, 40.0, 1e-4}); }
TEST(Viscosity, MeetsItsToleranceAsOneSystemComparableComponents) { checkWholeSystemTolerance<2>({48, 1.28, 1.0}); }

// A component that is exactly at rest with no wall moving along it stays at
// rest (a zero right-hand side is solved, not divided by).
TEST(Viscosity, ComponentAtRestStaysAtRest) {
  DomainBoundaries b;
  b.sides[3].wallVelocity = {1.0, 0.0, 0.0};
  const IVec<2> cells(32);
  const double h = 1.0 / 32;
  VelocityConstraints<2> vc(cells, h, b, Grid<uint8_t, 2>(cells, 0));
  MacVelocity<2> u = startingFlow<2>(vc, 0.0);
  ViscositySolver<2> solver(vc, SolverOptions{1e-6, 500});
  const SolverResult r = solver.diffuse(&u, 0.01, 1.28 * h * h / 0.01);
  EXPECT_TRUE(r.converged);
  for (float v : u[1].values()) ASSERT_EQ(v, 0.0f);
  for (float v : u[0].values()) ASSERT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace morphoflow
