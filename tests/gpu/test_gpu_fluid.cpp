// The GPU's linear solvers and stable fluid against the CPU's (llvmpipe in
// CI): MGPCG on the pressure systems of closed, obstructed, open and
// periodic boxes meets the tolerance by the CPU's own residual; the fluid
// step agrees with the CPU's after many steps for every boundary kind and
// advection scheme, 2D and 3D, and the projected field is divergence-free.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/multigrid.h"
#include "core/pcg.h"
#include "core/random.h"
#include "fluid/fluid_solver.h"
#include "fluid/pressure_projection.h"
#include "fluid/viscosity.h"
#include "tests/gpu/gpu_context.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_multigrid.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_reduction.h"

using namespace morphoflow;

namespace {


FluidSettings box(std::vector<int> res, bool obstacle, bool channel, bool periodicSpan) {
  FluidSettings s;
  s.resolution = res;
  s.size.clear();
  for (int n : res) s.size.push_back(double(n) / res[0]);
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
  } else {
    s.boundaries.sides[3].wallVelocity = {1.0, 0.0, 0.0};  // a lid on y_max
  }
  if (periodicSpan) {
    const size_t a = res.size() == 3 ? 2 : 1;
    s.boundaries.sides[2 * a].kind = s.boundaries.sides[2 * a + 1].kind = BoundaryKind::Periodic;
  }
  return s;
}

// Solves the pressure system of `s` for a random right-hand side on the GPU
// and checks the residual in double on the CPU.
template <int D>
void pressureSolveMeetsTolerance(const FluidSettings& s) {
  FluidSolver<D> cpu(s);
  const LaplaceSystem<D>& A = cpu.projection().system();
  Vector b(A.size());
  for (size_t i = 0; i < b.size(); ++i) b[i] = A.diag[i] > 0 ? uniform01(7, 0, i) - 0.5 : 0.0;
  if (A.singular()) A.removeNullSpace(&b);
  GpuLaplace gA(A);
  GpuMultigrid M(Multigrid<D>(A), gA, MultigridOptions{});
  GpuPcg pcg(gA);
  GpuBuffer gb = GpuBuffer::of(b), gx(A.size() * sizeof(double));
  gx.zero();
  const SolverResult r = pcg.solve(&gb, &gx, &M, {1e-6, 200});
  const Vector x = gx.read<double>(A.size());
  Vector res(A.size());
  const double rel = A.residual(b, x, &res) / norm2(b);
  EXPECT_TRUE(r.converged) << r.residual;
  EXPECT_LE(rel, 1.01e-6);
  EXPECT_NEAR(rel, r.residual, 1e-8);
  // The same preconditioner as the CPU's MGPCG: about its iteration count.
  Multigrid<D> cpuM(A);
  Vector cx(A.size(), 0.0);
  const SolverResult c = solvePCG<D>(A, b, &cx, &cpuM, {1e-6, 200});
  EXPECT_LE(r.iterations, c.iterations + 2) << "cpu " << c.iterations;
  EXPECT_GE(r.iterations, 2);
}

// One V-cycle of the pressure system of `s` on a random residual (the
// pressure's cycle, boundary smoothing and all), with its coarse levels in
// one dispatch (vcycle_tail.comp) and with a dispatch a pass: the same z,
// bit for bit. Returns the levels the tail ran.
template <int D>
int tailCycleMatchesTheLevelByLevelOne(const FluidSettings& s) {
  FluidSolver<D> cpu(s);
  const LaplaceSystem<D>& A = cpu.projection().system();
  const size_t n = A.size();
  Vector r(n);
  for (size_t i = 0; i < n; ++i) r[i] = A.diag[i] > 0 ? uniform01(11, 0, i) - 0.5 : 0.0;
  GpuLaplace gA(A);
  const Multigrid<D> levels(A, kPressureCycle);
  GpuMultigrid tail(levels, gA, kPressureCycle), each(levels, gA, kPressureCycle, 0);
  EXPECT_EQ(each.tailLevels(), 0);
  GpuReduction sums;
  GpuBuffer gr = GpuBuffer::of(r), z1(n * sizeof(double)), z2(n * sizeof(double));
  sums.dot(gr, gr, n, 0);
  tail.apply(gr, &z1, sums.scalars(), 0, sums.fused(1));
  each.apply(gr, &z2, sums.scalars(), 0, sums.fused(2));
  const Vector a = z1.read<double>(n), b = z2.read<double>(n);
  size_t differ = 0;
  for (size_t i = 0; i < n; ++i) differ += std::memcmp(&a[i], &b[i], sizeof(double)) != 0;
  EXPECT_EQ(differ, 0u);
  double zz = 0;
  for (double v : a) zz += v * v;
  EXPECT_GT(zz, 0.0);
  return tail.tailLevels();
}

// The viscous systems of `s`'s velocity components at nu dt / h^2 = 3, each
// solved by its own PCG in one shared set of work vectors (GpuViscosity's
// layout): every component meets the relative residual by the CPU's own
// residual, so the whole velocity system meets it too (sum_a ||r_a||^2 <=
// tol^2 sum_a ||b_a||^2); the solves' tallies, read together, say so.
// Returns the most iterations a component took.
template <int D>
int componentSolvesShareTheirWork(const FluidSettings& s) {
  FluidSolver<D> cpu(s);
  std::vector<ViscousSystem<D>> V;
  size_t most = 0;
  for (int a = 0; a < D; ++a) {
    V.push_back(viscousSystem<D>(cpu.constraints(), a));
    V.back().setRate(3.0);
    most = std::max(most, V.back().A.size());
  }
  auto work = std::make_shared<GpuPcgWork>(most, GpuPrecision::Double);
  std::vector<std::unique_ptr<GpuLaplace>> systems;
  std::vector<std::unique_ptr<GpuPcg>> solves;
  double rr = 0, bb = 0;
  int iterations = 0;
  for (int a = 0; a < D; ++a) {
    const LaplaceSystem<D>& A = V[size_t(a)].A;
    systems.push_back(std::make_unique<GpuLaplace>(A));
    solves.push_back(std::make_unique<GpuPcg>(*systems.back(), work));
    Vector b(A.size());  // zero on the inactive (prescribed) unknowns, as the viscosity's setup does
    for (size_t i = 0; i < A.size(); ++i) b[i] = A.diag[i] > 0 ? uniform01(6, uint64_t(a), i) - 0.5 : 0.0;
    GpuBuffer gb = GpuBuffer::of(b), gx(A.size() * sizeof(double));
    gx.zero();
    const SolverResult r = solves.back()->solve(&gb, &gx, nullptr, {1e-6, 500});
    const Vector x = gx.read<double>(A.size());
    Vector ra(A.size());
    const double na = A.residual(b, x, &ra);
    EXPECT_TRUE(r.converged) << a << " " << r.residual;
    EXPECT_LE(na / norm2(b), 1.01e-6) << a;
    EXPECT_NEAR(na / norm2(b), r.residual, 1e-8) << a;
    rr += na * na;
    bb += norm2(b) * norm2(b);
    iterations = std::max(iterations, r.iterations);
  }
  EXPECT_LE(std::sqrt(rr / bb), 1.01e-6);
  std::vector<GpuPcg*> all;
  for (auto& p : solves) all.push_back(p.get());
  for (const SolverResult& t : GpuPcg::tally(all)) EXPECT_TRUE(t.converged);
  return iterations;
}

// One V-cycle of the pressure's (kPressureCycle) on a cut body's system, on
// the device and on the host: the same z to single precision, and the host's
// without the band's sweeps much further off. Returns the relative
// difference between the two backends, and between the host's cycles with and
// without the band's sweeps.
template <int D>
std::pair<double, double> bandedCycleMatchesTheHost(const FluidSettings& s) {
  FluidSolver<D> cpu(s);
  const LaplaceSystem<D>& A = cpu.projection().system();
  const size_t n = A.size();
  Vector r(n);
  for (size_t i = 0; i < n; ++i) r[i] = A.diag[i] > 0 ? uniform01(13, 0, i) - 0.5 : 0.0;
  A.removeNullSpace(&r);
  Multigrid<D> levels(A, kPressureCycle), plainLevels(A);
  EXPECT_FALSE(levels.band(0).empty());
  Vector host, plain;
  levels.apply(r, &host);
  plainLevels.apply(r, &plain);
  GpuLaplace gA(A);
  GpuMultigrid M(levels, gA, kPressureCycle);
  GpuReduction sums;
  GpuBuffer gr = GpuBuffer::of(r), z(n * sizeof(double));
  sums.dot(gr, gr, n, 0);
  M.apply(gr, &z, sums.scalars(), 0, sums.fused(1));
  Vector device = z.read<double>(n);
  if (A.singular())  // (the cycles may leave different constants, which A maps to zero)
    for (Vector* v : {&device, &host, &plain}) A.removeNullSpace(v);
  double dd = 0, dp = 0, hh = 0;
  for (size_t i = 0; i < n; ++i) {
    dd += (device[i] - host[i]) * (device[i] - host[i]);
    dp += (plain[i] - host[i]) * (plain[i] - host[i]);
    hh += host[i] * host[i];
  }
  return {std::sqrt(dd / hh), std::sqrt(dp / hh)};
}

}  // namespace

TEST(GpuSolvers, TheVCycleSweepsTheBoundaryBandAsTheHostDoes) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (const auto& [device, plain] : {bandedCycleMatchesTheHost<2>(box({128, 128}, true, false, false)),
                                      bandedCycleMatchesTheHost<2>(box({96, 48}, true, true, true)),
                                      bandedCycleMatchesTheHost<3>(box({32, 32, 32}, true, false, false))}) {
    EXPECT_LT(device, 1e-5);
    EXPECT_GT(plain, 100 * device);
  }
}

TEST(GpuSolvers, TheViscousComponentsSolvesShareTheirWorkAndMeetTheWholeSystemsTolerance) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  EXPECT_GE(componentSolvesShareTheirWork<2>(box({48, 40}, false, false, false)), 5);  // the lid's cavity
  EXPECT_GE(componentSolvesShareTheirWork<2>(box({64, 32}, true, true, true)), 5);     // obstacle, channel, periodic
  EXPECT_GE(componentSolvesShareTheirWork<3>(box({16, 12, 10}, true, true, false)), 5);
}

TEST(GpuSolvers, TheVCyclesCoarseLevelsInOneDispatchAreBitwiseTheLevelByLevelCycle) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  EXPECT_EQ(tailCycleMatchesTheLevelByLevelOne<2>(box({128, 128}, false, false, false)), 5);  // 64^2 .. 4^2
  EXPECT_GE(tailCycleMatchesTheLevelByLevelOne<2>(box({96, 48}, true, true, false)), 2);
  EXPECT_GE(tailCycleMatchesTheLevelByLevelOne<2>(box({64, 32}, true, true, true)), 2);
  EXPECT_GE(tailCycleMatchesTheLevelByLevelOne<3>(box({24, 24, 24}, false, false, false)), 2);
  EXPECT_GE(tailCycleMatchesTheLevelByLevelOne<3>(box({32, 16, 16}, true, true, true)), 2);
}

TEST(GpuSolvers, MgpcgMeetsThePressureToleranceOnEveryKindOfBox) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  pressureSolveMeetsTolerance<2>(box({64, 64}, false, false, false));   // closed: singular
  pressureSolveMeetsTolerance<2>(box({96, 48}, true, true, false));     // obstacle, inflow, outflow
  pressureSolveMeetsTolerance<2>(box({64, 32}, true, true, true));      // periodic span
  pressureSolveMeetsTolerance<3>(box({24, 24, 24}, false, false, false));
  pressureSolveMeetsTolerance<3>(box({32, 16, 16}, true, true, true));
}

namespace {

// Runs `steps` steps on both backends from the same start (a dye
// checkerboard for the buoyant cases) and returns the largest difference of
// any velocity component over the largest speed, and of the dye.
template <int D>
std::pair<double, double> fluidDifference(const FluidSettings& s, int steps, double dt) {
  FluidSolver<D> cpu(s);
  forEachCell<D>(cpu.cells(), [&](const IVec<D>& k, size_t i) {
    cpu.dye()[i] = ((k[0] / 4 + k[1] / 4) % 2 == 0 && !cpu.solid()[i]) ? 1.0f : 0.0f;
  });
  GpuFluid<D> gpu(s, cpu.constraints());
  gpu.upload(cpu.velocity(), cpu.dye());
  for (int n = 0; n < steps; ++n) {
    cpu.step(dt);
    gpu.step(dt);
    EXPECT_TRUE(gpu.lastStats().pressure.converged) << "step " << n;
    EXPECT_TRUE(gpu.lastStats().viscosity.converged) << "step " << n;
  }
  MacVelocity<D> u = cpu.velocity();
  Grid<float, D> dye = cpu.dye();
  gpu.download(&u, &dye);
  double du = 0, umax = 0, dd = 0;
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      du = std::max(du, double(std::abs(u[a][i] - cpu.velocity()[a][i])));
      umax = std::max(umax, double(std::abs(cpu.velocity()[a][i])));
    }
  for (size_t i = 0; i < dye.size(); ++i) dd = std::max(dd, double(std::abs(dye[i] - cpu.dye()[i])));
  EXPECT_GT(umax, 0.1);
  return {du / umax, dd};
}

}  // namespace

// With the linear solves converged far below float rounding (1e-10), the
// two backends take the same steps: after tens of steps every velocity
// component agrees to float rounding of the largest speed, for every
// advection scheme and boundary kind (lid, inflow, outflow, obstacle,
// periodic sides, buoyancy, body force, inflow dye).
TEST(GpuFluid, EveryBoundaryKindAndSchemeMatchesTheCpuToRounding) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  auto tight = [](FluidSettings s, double nu) {
    s.viscosity = nu;
    s.pressureTolerance = s.viscosityTolerance = 1e-10;
    return s;
  };
  for (AdvectionScheme scheme :
       {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::Bfecc}) {
    FluidSettings s = tight(box({48, 48}, false, false, false), 1e-3);
    s.advection = scheme;
    const auto [du, dd] = fluidDifference<2>(s, 60, 0.01);
    EXPECT_LT(du, 1e-5) << "cavity, scheme " << int(scheme);
    EXPECT_LT(dd, 1e-4) << "cavity, scheme " << int(scheme);
  }
  FluidSettings c = tight(box({64, 32}, true, true, false), 2e-3);
  c.buoyancy = 0.5;
  c.inflowDyeStripes = 3;
  auto [du, dd] = fluidDifference<2>(c, 60, 0.01);
  EXPECT_LT(du, 1e-5) << "channel";
  EXPECT_LT(dd, 1e-4) << "channel";
  FluidSettings p = tight(box({32, 16, 16}, true, true, true), 2e-3);
  p.force = {0.0, 0.0, 0.3};
  std::tie(du, dd) = fluidDifference<3>(p, 30, 0.02);
  EXPECT_LT(du, 1e-5) << "3D channel";
  std::tie(du, dd) = fluidDifference<3>(tight(box({24, 16, 16}, false, false, false), 2e-3), 30, 0.02);
  EXPECT_LT(du, 1e-5) << "3D cavity";
}

// At a scene's tolerance (1e-6) each backend's solve leaves its own error of
// that size, and the MacCormack limiter, which switches a sample to first
// order where the correction leaves the stencil's range, amplifies such a
// difference where it switches on one backend and not the other: a few
// 1e-4 of the largest speed (docs/gpu.md), while both projections converge.
TEST(GpuFluid, AtTheSceneToleranceTheBackendsAgreeToTheLimitersSensitivity) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  FluidSettings s = box({24, 16, 16}, false, false, false);
  s.viscosity = 2e-3;
  const auto [du, dd] = fluidDifference<3>(s, 30, 0.02);
  EXPECT_LT(du, 2e-3);
  EXPECT_LT(dd, 2e-3);
}

namespace {

// The fluid with every smoke stage: a fixed source of smoke and heat, a
// moving one, an injecting one, buoyancy with weight, confinement,
// dissipation and cooling (fluid/smoke.h, shaders/smoke.comp).
FluidSettings smoky(std::vector<int> res) {
  FluidSettings s = box(res, false, false, false);
  s.boundaries.sides[3].wallVelocity = {0.0, 0.0, 0.0};
  s.boundaries.sides[3].kind = BoundaryKind::Outflow;
  s.viscosity = 1e-3;
  s.pressureTolerance = s.viscosityTolerance = 1e-10;
  SmokeSettings& m = s.smoke;
  m.enabled = true;
  m.heat = 1.5;
  m.weight = 0.2;
  m.ambient = 0.1;
  m.vorticity = 1.0;
  m.dissipation = 0.3;
  m.cooling = 0.5;
  const bool three = res.size() == 3;
  SmokeSource a;
  a.region.shape = three ? ObstacleShape::Sphere : ObstacleShape::Circle;
  a.region.center = {0.5, 0.2, 0.5};
  a.region.radius = 0.12;
  a.density = 2.0;
  a.temperature = 4.0;
  SmokeSource b = a;
  b.region.radius = 0.08;
  b.motion = three ? std::vector<std::string>{"0.3 + 0.3 * t", "0.3", "0.5"}
                   : std::vector<std::string>{"0.3 + 0.3 * t", "0.3"};
  b.start = 0.05;
  SmokeSource c = a;
  c.region.shape = ObstacleShape::Box;
  c.region.center = {0.8, 0.5, 0.5};
  c.region.halfSize = {0.05, 0.1, 0.1};
  c.density = 0.0;
  c.inject = true;
  c.velocity = {-0.5, 0.2, 0.0};
  c.end = 0.3;
  m.sources = {a, b, c};
  return s;
}

// The GPU's velocity, smoke and temperature within `tolerance` of their largest values.
template <int D>
void expectSmokeMatches(const FluidSettings& s, int steps, double dt, GpuPrecision real = GpuPrecision::Double,
                        double tolerance = 1e-5) {
  FluidSolver<D> cpu(s);
  GpuFluid<D> gpu(s, cpu.constraints(), real);
  gpu.upload(cpu.velocity(), cpu.dye(), &cpu.temperature());
  for (int n = 0; n < steps; ++n) cpu.step(dt), gpu.step(dt);
  MacVelocity<D> u = cpu.velocity();
  Grid<float, D> dye = cpu.dye(), temp = cpu.temperature();
  gpu.download(&u, &dye, &temp);
  double du = 0, umax = 0, dd = 0, dmax = 0, dt2 = 0, tmax = 0;
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      du = std::max(du, double(std::abs(u[a][i] - cpu.velocity()[a][i])));
      umax = std::max(umax, double(std::abs(cpu.velocity()[a][i])));
    }
  for (size_t i = 0; i < dye.size(); ++i) {
    dd = std::max(dd, double(std::abs(dye[i] - cpu.dye()[i])));
    dmax = std::max(dmax, double(cpu.dye()[i]));
    dt2 = std::max(dt2, double(std::abs(temp[i] - cpu.temperature()[i])));
    tmax = std::max(tmax, double(cpu.temperature()[i]));
  }
  EXPECT_GT(umax, 0.05);
  EXPECT_GT(dmax, 0.05);
  EXPECT_LT(du / umax, tolerance) << D << "D velocity";
  EXPECT_LT(dd / dmax, tolerance) << D << "D smoke";
  EXPECT_LT(dt2 / tmax, tolerance) << D << "D temperature";
}

}  // namespace

// Smoke on the GPU: sources (fixed, moving, injecting), buoyancy, vorticity
// confinement, dissipation and cooling take the CPU's steps, 2D and 3D, to
// float rounding of the largest value in double (measured: 2e-7 in 2D, 4e-7
// in 3D), and within 1e-4 in float, its solves at float's floor (measured
// 1.4e-5 in 2D, 1.2e-6 in 3D).
TEST(GpuFluid, SmokeMatchesTheCpu) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  expectSmokeMatches<2>(smoky({48, 48}), 40, 0.01);
  expectSmokeMatches<3>(smoky({20, 20, 20}), 20, 0.02);
  expectSmokeMatches<2>(smoky({48, 48}), 40, 0.01, GpuPrecision::Float, 1e-4);
  expectSmokeMatches<3>(smoky({20, 20, 20}), 20, 0.02, GpuPrecision::Float, 1e-4);
}

namespace {

// A closed box stirred by a body crossing it (a circle, or a sphere in 3D)
// and, in 2D, a turning paddle (obstacles.N.motion and rotation), its
// solves converged far below float rounding.
FluidSettings stirred(std::vector<int> res, ObstacleBoundary boundary = ObstacleBoundary::Cut) {
  FluidSettings s = box(res, false, false, false);
  s.boundaries.sides[3].wallVelocity = {0.0, 0.0, 0.0};
  s.viscosity = 2e-3;
  s.pressureTolerance = s.viscosityTolerance = 1e-10;
  s.advection = AdvectionScheme::MacCormack;
  const bool three = res.size() == 3;
  ObstacleSpec body;
  body.shape = three ? ObstacleShape::Sphere : ObstacleShape::Circle;
  body.radius = 0.12;
  body.boundary = boundary;
  body.motion = three ? std::vector<std::string>{"0.3 + 0.8 * t", "0.5", "0.5"}
                      : std::vector<std::string>{"0.3 + 0.8 * t", "0.35"};
  s.obstacles.push_back(body);
  if (!three) {
    ObstacleSpec paddle;
    paddle.shape = ObstacleShape::Box;
    paddle.center = {0.65, 0.72, 0.0};
    paddle.halfSize = {0.16, 0.03, 0.0};
    paddle.boundary = boundary;
    paddle.rotation = {"4 * t"};
    s.obstacles.push_back(paddle);
  }
  return s;
}

}  // namespace

// Moving obstacles on the GPU: the host places them at every step (their
// geometry depends on the time alone) and the device's constraints, solid
// flux, pressure system and levels and viscous systems follow; the cells
// they uncover are filled on the device from the host's plan. A towed
// circle with a turning paddle (cut and staircase boundaries), a towed
// sphere, and a smoke with its temperature stirred by them take the CPU's
// steps to float rounding of the largest speed (measured 2.1e-7, 2.0e-7
// and 1.5e-7 of it; the dye within 1.2e-6).
TEST(GpuFluid, MovingObstaclesMatchTheCpuToRounding) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (ObstacleBoundary b : {ObstacleBoundary::Cut, ObstacleBoundary::Voxel}) {
    const auto [du, dd] = fluidDifference<2>(stirred({48, 48}, b), 40, 0.01);
    EXPECT_LT(du, 1e-5) << "circle and paddle, boundary " << int(b);
    EXPECT_LT(dd, 1e-4) << "circle and paddle, boundary " << int(b);
  }
  const auto [du, dd] = fluidDifference<3>(stirred({20, 20, 20}), 20, 0.02);
  EXPECT_LT(du, 1e-5) << "sphere";
  EXPECT_LT(dd, 1e-4) << "sphere";
  FluidSettings smoke = smoky({48, 48});
  smoke.obstacles = stirred({48, 48}).obstacles;
  expectSmokeMatches<2>(smoke, 40, 0.01);
}

namespace {

// How many of `device`'s elements differ in their bits from `host`'s.
template <class T>
size_t bitsDiffer(const std::vector<T>& device, const std::vector<T>& host) {
  size_t n = 0;
  for (size_t i = 0; i < host.size(); ++i) n += std::memcmp(&device[i], &host[i], sizeof(T)) != 0 ? 1 : 0;
  return n;
}

// The device's placement of the moving obstacles of `s` (gpu/fluid/gpu_obstacles.h) against the host's at
// each of `times`: the solid flags, the faces' fixed flags, held values and open fractions, and the solid
// flux, bitwise. Returns the cut faces (0 < open < 1) and the cells with a flux that were compared.
template <int D>
std::pair<size_t, size_t> expectDevicePlacementIsTheHosts(const FluidSettings& s, const std::vector<double>& times) {
  const FluidSolver<D> cpu(s);
  ObstaclePlacement<D> placement(s, cpu.constraints().cells, cpu.constraints().h);
  VelocityConstraints<D> host = placement.constraintsAt(0.0);
  GpuMacGrid<D> grid(host);
  GpuObstacles<D> device(s, &grid);
  device.place(placement.placed(), placement.motions(), IVec<D>(0), host.cells);
  size_t cutFaces = 0, fluxCells = 0;
  for (double t : times) {
    IVec<D> lo, hi;
    if (placement.moveTo(t, &host, &lo, &hi)) device.place(placement.placed(), placement.motions(), lo, hi);
    std::vector<uint32_t> solid(host.solid.values().begin(), host.solid.values().end());
    EXPECT_EQ(bitsDiffer(grid.solid.template read<uint32_t>(host.solid.size()), solid), 0u) << "solid, t = " << t;
    for (int a = 0; a < D; ++a) {
      const size_t n = grid.faces(a), at = grid.off[size_t(a)];
      const std::vector<uint8_t>& f = host.fixed[a].values();
      const std::vector<float> open = host.open[a].expandedRows(0, n / size_t(host.fixed[a].dims()[0]));
      EXPECT_EQ(bitsDiffer(grid.fixed.template read<uint32_t>(n, at * 4), std::vector<uint32_t>(f.begin(), f.end())),
                0u)
          << "fixed " << a << ", t = " << t;
      EXPECT_EQ(bitsDiffer(grid.value.template read<float>(n, at * 4), host.prescribedGrid(a)), 0u) << "value " << a;
      EXPECT_EQ(bitsDiffer(grid.open.template read<float>(n, at * 4), open), 0u) << "open " << a << ", t = " << t;
      cutFaces += size_t(std::count_if(open.begin(), open.end(), [](float o) { return o > 0.0f && o < 1.0f; }));
    }
    EXPECT_EQ(bitsDiffer(grid.solidFlux.template read<double>(host.solidFlux.size()), host.solidFlux), 0u)
        << "t = " << t;
    fluxCells += size_t(std::count_if(host.solidFlux.begin(), host.solidFlux.end(), [](double v) { return v != 0; }));
  }
  return {cutFaces, fluxCells};
}

}  // namespace

// The device places moving obstacles itself at every step
// (shaders/cut_geometry.comp, with the host's formulas: kernels/obstacle_shape.inc, cut_fraction.inc):
// its solid flags, fixed flags, held velocities, open fractions and solid
// flux are the host's to the bit for a towed circle with a turning paddle
// (cut and staircase), a towed sphere, a box turning about three axes, a
// circle and a sphere passing an sdf's and an image's disc, and a circle
// crossing a periodic seam beside an inflow.
TEST(GpuFluid, TheDevicePlacesMovingObstaclesAsTheHostDoes) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  const std::vector<double> times = {0.01, 0.02, 0.1, 0.37};
  for (ObstacleBoundary b : {ObstacleBoundary::Cut, ObstacleBoundary::Voxel}) {
    const auto [cut, flux] = expectDevicePlacementIsTheHosts<2>(stirred({48, 48}, b), times);
    if (b == ObstacleBoundary::Cut) {
      EXPECT_GT(cut, 100u);
    }
    EXPECT_GT(flux, 50u) << int(b);
  }
  const auto [cut3, flux3] = expectDevicePlacementIsTheHosts<3>(stirred({20, 20, 20}), times);
  EXPECT_GT(cut3, 100u);
  EXPECT_GT(flux3, 20u);
  FluidSettings turning = box({20, 20, 20}, false, false, false);
  ObstacleSpec paddle;
  paddle.shape = ObstacleShape::Box;
  paddle.center = {0.5, 0.5, 0.5};
  paddle.halfSize = {0.3, 0.08, 0.15};
  paddle.rotation = {"2 * t", "3 * t", "5 * t"};
  turning.obstacles = {paddle};
  EXPECT_GT(expectDevicePlacementIsTheHosts<3>(turning, times).first, 100u);
  // A sphere (a circle in 2D) that passes a disc given as a signed-distance
  // picture and one given as a grey picture (only a sign: its cut faces found
  // by bisection in 2D, 8 x 8 samples in 3D); the pictures do not move.
  for (ObstacleShape shape : {ObstacleShape::Sdf, ObstacleShape::Image}) {
    ObstacleSpec disc;
    disc.shape = shape;
    disc.fieldWidth = disc.fieldHeight = 40;
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i) {
        const double d = std::hypot((i + 0.5) / 40 - 0.6, 1.0 - (j + 0.5) / 40 - 0.55) - 0.2;
        disc.field.push_back(float(shape == ObstacleShape::Sdf ? d : std::clamp(0.5 - 40 * d, 0.0, 1.0)));
      }
    FluidSettings two = stirred({48, 48}), three = stirred({20, 20, 20});
    two.obstacles.push_back(disc);
    three.obstacles.push_back(disc);
    EXPECT_GT(expectDevicePlacementIsTheHosts<2>(two, times).first, 100u) << int(shape);
    EXPECT_GT(expectDevicePlacementIsTheHosts<3>(three, times).first, 100u) << int(shape);
  }
  FluidSettings seam = box({48, 32}, false, true, true);  // inflow at x = 0, periodic in y
  ObstacleSpec body;
  body.radius = 0.1;
  body.motion = {"0.5", "0.6 + 2 * t"};  // across the seam at y = 2/3, its centre from t = 0.03 on
  seam.obstacles = {body};
  EXPECT_GT(expectDevicePlacementIsTheHosts<2>(seam, times).second, 20u);
}
