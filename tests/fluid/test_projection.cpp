// Pressure projection: the projected field is divergence-free to the
// solver's tolerance, with obstacles, outflow and periodic sides, 2D and 3D.
#include <gtest/gtest.h>

#include <cmath>

#include "core/multigrid.h"
#include "core/pcg.h"
#include "core/random.h"
#include "fluid/fluid_solver.h"
#include "fluid/pressure_projection.h"

using namespace morphoflow;

namespace {

FluidSettings box(std::vector<int> res, bool obstacle, bool channel, PressureSolver solver) {
  FluidSettings s;
  s.resolution = res;
  s.size.clear();
  for (int n : res) s.size.push_back(double(n) / res[0]);
  s.pressureSolver = solver;
  s.pressureTolerance = 1e-6;
  if (obstacle) {
    ObstacleSpec o;
    o.shape = res.size() == 3 ? ObstacleShape::Sphere : ObstacleShape::Circle;
    o.center = {0.4, 0.5 * s.size[1], res.size() == 3 ? 0.5 * s.size[2] : 0.0};
    o.radius = 0.15 * s.size[1];
    s.obstacles.push_back(o);
  }
  if (channel) {
    s.boundaries.sides[0].kind = BoundaryKind::Inflow;
    s.boundaries.sides[1].kind = BoundaryKind::Outflow;
    if (res.size() == 3) {  // periodic span
      s.boundaries.sides[4].kind = BoundaryKind::Periodic;
      s.boundaries.sides[5].kind = BoundaryKind::Periodic;
    }
  }
  return s;
}

// The cell divergence written plainly (each face through the grid's
// coordinates, weighed by its open fraction: the cut obstacle's), 0 in cells
// without a pressure: the reference for the projection's own.
template <int D>
Vector plainDivergence(FluidSolver<D>& f) {
  const MacVelocity<D>& u = f.velocity();
  const VelocityConstraints<D>& vc = f.constraints();
  Vector div(vc.solid.size(), 0.0);
  forEachCell<D>(vc.cells, [&](const IVec<D>& k, size_t i) {
    if (f.projection().system().diag[i] == 0.0f) return;
    double d = 0.0;
    for (int a = 0; a < D; ++a) {
      const IVec<D> up = k + unitVector<D>(a);
      d += double(vc.open[a](up)) * double(u[a](up)) - double(vc.open[a](k)) * double(u[a](k));
    }
    div[i] = d / vc.h;
  });
  return div;
}

template <int D>
double divergenceNorm(FluidSolver<D>& f) {
  const Vector div = plainDivergence(f);
  // The projection's row-wise divergence agrees with the plain one.
  Vector own;
  f.projection().divergence(f.velocity(), &own);
  EXPECT_EQ(own.size(), div.size());
  double worst = 0.0, scale = 0.0;
  for (size_t i = 0; i < div.size(); ++i) {
    worst = std::max(worst, std::abs(own[i] - div[i]));
    scale = std::max(scale, std::abs(div[i]));
  }
  EXPECT_LE(worst, 1e-12 * scale);
  return norm2(div);
}

template <int D>
void checkProjection(const FluidSettings& s) {
  FluidSolver<D> f(s);
  MacVelocity<D>& u = f.velocity();
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) u[a][i] = float(2.0 * uniform01(7, uint64_t(a), i) - 1.0);
  f.constraints().apply(&u);
  double before = divergenceNorm(f);
  ASSERT_GT(before, 0);
  SolverResult r = f.projection().project(&u, 0.01, 1.0);
  EXPECT_TRUE(r.converged) << "iterations " << r.iterations << " residual " << r.residual;
  EXPECT_LE(r.residual, 1e-6);
  double after = divergenceNorm(f);
  // Velocities are stored in float: allow a few ulps on top of the tolerance.
  EXPECT_LT(after / before, 5e-6) << "div before " << before << " after " << after;
  // Prescribed faces keep their values: nothing flows into a solid.
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i)
      if (f.constraints().fixed[a][i]) {
        ASSERT_EQ(u[a][i], f.constraints().prescribed(a, i));
      }
}

}  // namespace

std::string solverName(const ::testing::TestParamInfo<PressureSolver>& info) {
  static const char* names[] = {"MGPCG", "ICPCG", "Multigrid"};
  return names[int(info.param)];
}

class Projection : public ::testing::TestWithParam<PressureSolver> {};

TEST_P(Projection, RandomField2DClosedBox) { checkProjection<2>(box({64, 64}, false, false, GetParam())); }
TEST_P(Projection, RandomField2DObstacleChannel) { checkProjection<2>(box({96, 48}, true, true, GetParam())); }
TEST_P(Projection, RandomField3DObstacle) { checkProjection<3>(box({24, 24, 24}, true, false, GetParam())); }
TEST_P(Projection, RandomField3DChannelPeriodicSpan) {
  checkProjection<3>(box({32, 16, 16}, true, true, GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Solvers, Projection,
                         ::testing::Values(PressureSolver::MGPCG, PressureSolver::ICPCG, PressureSolver::Multigrid),
                         solverName);

TEST(Projection, ProjectingTwiceChangesNothing) {
  // A divergence-free field is a fixed point of the projection.
  FluidSolver<2> f(box({48, 48}, true, false, PressureSolver::MGPCG));
  MacVelocity<2>& u = f.velocity();
  for (int a = 0; a < 2; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) u[a][i] = float(uniform01(3, uint64_t(a), i) - 0.5);
  f.constraints().apply(&u);
  f.projection().project(&u, 0.01, 1.0);
  MacVelocity<2> once = u;
  f.projection().project(&u, 0.01, 1.0);
  double diff = 0, mag = 0;
  for (int a = 0; a < 2; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      diff = std::max(diff, double(std::abs(u[a][i] - once[a][i])));
      mag = std::max(mag, double(std::abs(once[a][i])));
    }
  EXPECT_LT(diff, 1e-4 * mag);
}

// A CFL-limited run changes dt every step: the viscosity rescales its
// systems and re-derives its multigrid levels in place, and both solves start
// from extrapolated guesses. Each step must still give the flow of a solver
// that starts cold from the same velocity (to the tolerances), and the warm
// starts must save iterations. One step jumps to s = nu dt / h^2 = 38, past
// the point (about 30 in 2D) where the viscosity switches from the
// Chebyshev iteration to multigrid-preconditioned CG, and one drops to
// s = 0.06; both come back.
TEST(Projection, WarmStartsAcrossChangingStepsGiveTheColdSolution) {
  FluidSettings s;
  s.resolution = {128, 128};
  s.size = {1.0, 1.0};
  s.viscosity = 0.01;
  s.boundaries.sides[3].wallVelocity = {1.0, 0.0, 0.0};  // the lid
  s.pressureTolerance = 1e-8;
  s.viscosityTolerance = 1e-8;
  FluidSolver<2> warm(s);
  const double h = warm.h();
  for (int k = 0; k < 20; ++k) warm.step(h);  // past the impulsive start
  // A CFL limit moves dt smoothly; one step jumps far up, one far down.
  const double factors[] = {1.0, 1.05, 1.1, 1.16, 1.2, 1.22, 30.0, 1.2, 1.15, 1.1, 0.05, 1.04, 1.0};
  int warmIterations = 0, coldIterations = 0;
  double worst = 0.0;
  for (int k = 0; k < 13; ++k) {
    const double dt = factors[k] * h;  // s = 1.28 * factor
    FluidSolver<2> cold(s);
    cold.velocity() = warm.velocity();
    warm.step(dt);
    cold.step(dt);
    // Both warm starts are in use from the third step; a jump of 25x in dt
    // (and the step after it) extrapolates far from the last steps' rates,
    // so the savings are counted over the smooth changes.
    if (k >= 2 && factors[k] < 2.0 && factors[k - 1] < 2.0) {
      warmIterations += warm.lastStats().viscosity.iterations + warm.lastStats().pressure.iterations;
      coldIterations += cold.lastStats().viscosity.iterations + cold.lastStats().pressure.iterations;
    }
    ASSERT_TRUE(warm.lastStats().viscosity.converged && warm.lastStats().pressure.converged) << "step " << k;
    double diff = 0.0, mag = 0.0;
    for (int a = 0; a < 2; ++a)
      for (size_t i = 0; i < warm.velocity()[a].size(); ++i) {
        diff = std::max(diff, double(std::abs(warm.velocity()[a][i] - cold.velocity()[a][i])));
        mag = std::max(mag, double(std::abs(cold.velocity()[a][i])));
      }
    worst = std::max(worst, diff / mag);
  }
  EXPECT_LT(worst, 1e-5);  // float velocities, solves to 1e-8
  EXPECT_LT(double(warmIterations), 0.9 * coldIterations) << warmIterations << " warm, " << coldIterations << " cold";
}

// Boundary smoothing (core/boundary_band.h) in the pressure's V-cycle: a
// cut sphere's system, at places along the circle a moving one takes,
// solved by MGPCG from zero for a random mean-free right-hand side to
// 1e-6, with and without the band's sweeps.
TEST(Projection, BoundarySmoothingTakesFewerIterationsForACutSphere) {
  int with = 0, without = 0;
  for (int place = 0; place < 6; ++place) {
    FluidSettings s = box({64, 64, 64}, true, false, PressureSolver::MGPCG);
    const double t = 0.02 * place;
    s.obstacles[0].center = {0.5 + 0.2 * std::cos(t), 0.5 + 0.2 * std::sin(t), 0.5};
    FluidSolver<3> f(s);
    const LaplaceSystem<3>& A = f.projection().system();
    Vector b(A.size());
    for (size_t i = 0; i < b.size(); ++i) b[i] = A.diag[i] > 0 ? uniform01(3, uint64_t(place), i) - 0.5 : 0.0;
    A.removeNullSpace(&b);
    int its[2] = {0, 0};
    for (int banded = 0; banded < 2; ++banded) {
      Multigrid<3> M(A, banded ? kPressureCycle : MultigridOptions{});
      EXPECT_EQ(M.band(0).empty(), !banded);
      Vector x(A.size(), 0.0);
      const SolverResult r = solvePCG<3>(A, b, &x, &M, {1e-6, 100});
      EXPECT_TRUE(r.converged);
      its[banded] = r.iterations;
    }
    EXPECT_LE(its[1], its[0]) << "place " << place;
    without += its[0], with += its[1];
  }
  EXPECT_LT(with, without);  // (7 to 9 iterations each without, 6 with, on this mesh)
}
