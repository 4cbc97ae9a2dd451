// The advection-reaction-diffusion coupling (seed 001 sec. 5, 7): a chemical
// carried once around a rigid rotation returns to its start (cubic closer
// than linear, on an RD grid finer than the fluid's); a coupled cavity at a
// large time step stays bounded; the serial and tbb-overlap schedulers give
// bitwise-identical fields for any thread count; inflow and obstacles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <thread>

#include "core/parallel.h"
#include "core/simd_dispatch.h"
#include "core/random.h"
#include "coupling/cpu_coupled_stepper.h"
#include "rd/model_registry.h"

using namespace morphoflow;

namespace {

// Rigid rotation about the centre of the unit square, omega = 2 pi (period 1).
MacVelocity<2> rotation(int n) {
  MacVelocity<2> u(IVec<2>(n, n), 1.0 / n, {false, false});
  const double h = 1.0 / n, w = 2 * M_PI;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i <= n; ++i) u[0](IVec<2>(i, j)) = float(-w * ((j + 0.5) * h - 0.5));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i < n; ++i) u[1](IVec<2>(i, j)) = float(w * ((i + 0.5) * h - 0.5));
  return u;
}

Grid<double, 2> blob(int n) {
  Grid<double, 2> g(IVec<2>(n, n));
  forEachCell<2>(g.dims(), [&](const IVec<2>& k, size_t i) {
    const double x = (k[0] + 0.5) / n - 0.72, y = (k[1] + 0.5) / n - 0.5;
    g[i] = std::exp(-(x * x + y * y) / (2 * 0.06 * 0.06));
  });
  return g;
}

// The relative L1 error of g's return after one turn of the rotation (the
// fluid on fluidCells^2), in `steps` steps of the midpoint trace.
double turnError(ChemicalInterpolation interp, int fluidCells, Grid<double, 2> g, int steps) {
  MacVelocity<2> u = rotation(fluidCells);
  ChemicalDomain<2> d;
  d.cells = g.dims();
  d.h = 1.0 / g.dim(0);
  ChemicalAdvector<2> adv(d, interp);
  const Grid<double, 2> start = g;
  for (int s = 0; s < steps; ++s) adv.advect(u, 1.0 / steps, {&g});
  double err = 0, mass = 0;
  for (size_t i = 0; i < g.size(); ++i) err += std::abs(g[i] - start[i]), mass += std::abs(start[i]);
  return err / mass;
}

double roundTripError(ChemicalInterpolation interp, int rdCells, int steps) {
  return turnError(interp, 32, blob(rdCells), steps);  // the fluid grid: coarser than the chemical's
}

}  // namespace

TEST(ChemicalAdvection, RotationReturnsTheBlobToItsStart) {
  const double linear = roundTripError(ChemicalInterpolation::Linear, 96, 96);
  const double cubic = roundTripError(ChemicalInterpolation::Cubic, 96, 96);
  EXPECT_LT(linear, 0.6) << "linear interpolation diffuses, but the blob must come back";
  EXPECT_LT(cubic, 0.15);
  EXPECT_LT(cubic, 0.5 * linear) << "cubic must be measurably closer than linear";
  // Refining the chemical grid (same fluid grid) brings it closer.
  EXPECT_LT(roundTripError(ChemicalInterpolation::Cubic, 192, 192), 0.6 * cubic);
}

namespace {

// The measure of sharp transport: a Gaussian (sigma 0.06 at (0.5,
// 0.75)) rotated one turn about the centre of the unit square, n^2 cells for
// the fluid and the chemicals, `steps` steps of the midpoint trace; the
// relative L1 error of its return.
double rotationL1(ChemicalInterpolation interp, int n, int steps) {
  Grid<double, 2> g(IVec<2>(n, n));
  forEachCell<2>(g.dims(), [&](const IVec<2>& k, size_t i) {
    const double x = (k[0] + 0.5) / n - 0.5, y = (k[1] + 0.5) / n - 0.75;
    g[i] = std::exp(-(x * x + y * y) / (2 * 0.06 * 0.06));
  });
  return turnError(interp, n, g, steps);
}

}  // namespace

// coupling.interpolation = "bspline": at 128^2 with 1024 steps the blob comes
// back within 0.005 (relative L1; Catmull-Rom's is about 0.055), the error
// falls with resolution (64^2, 512 steps: at least 4 times larger), and it
// adds no extrema.
TEST(ChemicalAdvection, BSplineCarriesTheRotatedBlobSharply) {
  const double fine = rotationL1(ChemicalInterpolation::BSpline, 128, 1024);
  const double coarse = rotationL1(ChemicalInterpolation::BSpline, 64, 512);
  const double cubic = rotationL1(ChemicalInterpolation::Cubic, 128, 1024);
  ::testing::Test::RecordProperty("bspline_128", std::to_string(fine));
  ::testing::Test::RecordProperty("bspline_64", std::to_string(coarse));
  ::testing::Test::RecordProperty("cubic_128", std::to_string(cubic));
  EXPECT_LE(fine, 0.005) << "coarse " << coarse << ", cubic " << cubic;
  EXPECT_GE(coarse, 4.0 * fine) << "fine " << fine;
  EXPECT_LT(fine, 0.2 * cubic);
}

// coupling.interpolation = "bfecc": the error compensation makes the linear
// samples far sharper on the rotated blob (at least 5 times closer than
// linear at 128^2), the error falls with resolution, and the limiter keeps
// it bounded.
TEST(ChemicalAdvection, BFECCSharpensTheLinearSamples) {
  const double fine = rotationL1(ChemicalInterpolation::BFECC, 128, 1024);
  const double coarse = rotationL1(ChemicalInterpolation::BFECC, 64, 512);
  const double linear = rotationL1(ChemicalInterpolation::Linear, 128, 1024);
  ::testing::Test::RecordProperty("bfecc_128", std::to_string(fine));
  ::testing::Test::RecordProperty("bfecc_64", std::to_string(coarse));
  ::testing::Test::RecordProperty("linear_128", std::to_string(linear));
  EXPECT_LT(fine, 0.2 * linear) << "coarse " << coarse << ", linear " << linear;
  EXPECT_GE(coarse, 2.0 * fine) << "fine " << fine;
}

TEST(ChemicalAdvection, BSplineAndBFECCAddNoExtremaOnWallsAndPeriodicAxes) {
  MacVelocity<2> u = rotation(16);
  for (ChemicalInterpolation interp : {ChemicalInterpolation::BSpline, ChemicalInterpolation::BFECC}) {
    for (bool periodic : {false, true}) {
      ChemicalDomain<2> d;
      d.cells = IVec<2>(48, 48);
      d.h = 1.0 / 48;
      d.periodic = {periodic, periodic};
      ChemicalAdvector<2> adv(d, interp);
      Grid<double, 2> g(d.cells);
      for (size_t i = 0; i < g.size(); ++i) g[i] = (i / 48 + i % 48) % 7 < 3 ? 1.0 : 0.0;  // sharp stripes
      for (int s = 0; s < 40; ++s) adv.advect(u, 0.013, {&g});
      for (double v : g.values()) {
        EXPECT_GE(v, 0.0) << interpolationName(interp);
        EXPECT_LE(v, 1.0) << interpolationName(interp);
      }
    }
  }
}

TEST(ChemicalAdvection, CubicAddsNoExtrema) {
  MacVelocity<2> u = rotation(16);
  ChemicalDomain<2> d;
  d.cells = IVec<2>(48, 48);
  d.h = 1.0 / 48;
  ChemicalAdvector<2> adv(d, ChemicalInterpolation::Cubic);
  Grid<double, 2> g(d.cells);
  for (size_t i = 0; i < g.size(); ++i) g[i] = (i / 48 + i % 48) % 7 < 3 ? 1.0 : 0.0;  // sharp stripes
  for (int s = 0; s < 40; ++s) adv.advect(u, 0.013, {&g});
  for (double v : g.values()) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
  }
}

// Chemical entering through an inflow side: a uniform flow from x_min carries
// the inflow value across; cells inside an obstacle hold none.
TEST(ChemicalAdvection, InflowAndObstacles) {
  const int n = 32;
  MacVelocity<2> u(IVec<2>(n, n), 1.0 / n, {false, false});
  u[0].fill(1.0f);
  ChemicalDomain<2> d;
  d.cells = IVec<2>(n, n);
  d.h = 1.0 / n;
  d.inflow[0][0] = true;
  d.inflowValues = {0.7};
  d.solid.assign(size_t(n * n), 0);
  d.solid[size_t(16 * n + 20)] = 1;
  d.solidValues = {0.0};
  ChemicalAdvector<2> adv(d, ChemicalInterpolation::Linear);
  Grid<double, 2> g(d.cells, 0.2);
  for (int s = 0; s < 20; ++s) adv.advect(u, 0.5 / n, {&g});  // 10 cells of travel
  EXPECT_NEAR(g(IVec<2>(0, 5)), 0.7, 1e-12);
  EXPECT_NEAR(g(IVec<2>(2, 5)), 0.7, 1e-3);
  EXPECT_NEAR(g(IVec<2>(25, 5)), 0.2, 1e-12);
  // The chemical that entered: (0.7 - 0.2) times the 10 cells travelled,
  // within one cell (the front is point-sampled).
  double entered = 0;
  for (int i = 0; i < n; ++i) entered += g(IVec<2>(i, 5)) - 0.2;
  EXPECT_NEAR(entered, 0.5 * 10, 0.5);
  EXPECT_EQ(g(IVec<2>(20, 16)), 0.0);
}

// Obstacles hold no chemical in ARD mode; the RD-only comparison ignores the
// flow and its obstacles (seed 001 fig. 6), so there the solid cells react.
TEST(ARDSolver, ObstaclesHoldNoChemicalExceptInRDOnly) {
  const int n = 16;
  for (CouplingMode mode : {CouplingMode::ARD, CouplingMode::RDOnly}) {
    RDSettings s;
    s.model = "gray-scott";
    s.resolution = {n, n};
    s.size = {1.0, 1.0};
    s.diffusion = {1e-3, 5e-4};
    s.parameters = {0.04, 0.06};
    RDSolver<2> rd(s, *findModel("gray-scott"));
    rd.field(0).fill(0.5);
    rd.field(1).fill(0.25);
    ChemicalDomain<2> d;
    d.cells = rd.cells();
    d.h = rd.h();
    d.solid.assign(size_t(n * n), 0);
    const size_t ball = size_t(8 * n + 8);
    d.solid[ball] = 1;
    d.solidValues = {1.0, 0.0};
    ARDSolver<2> ard(&rd, ChemicalAdvector<2>(d, ChemicalInterpolation::Linear), mode, 1.0);
    MacVelocity<2> still(d.cells, d.h, {false, false});
    for (int i = 0; i < 3; ++i) ard.step(1.0, still);
    if (mode == CouplingMode::ARD) {
      EXPECT_EQ(rd.field(0)[ball], 1.0);
      EXPECT_EQ(rd.field(1)[ball], 0.0);
    } else {  // the uniform state reacts everywhere alike, the ball included
      EXPECT_GT(rd.field(1)[ball], 0.0);
      EXPECT_DOUBLE_EQ(rd.field(1)[ball], rd.field(1)[0]);
    }
  }
}

namespace {

template <int D>
FluidSettings cavity(int n, double re) {
  FluidSettings f;
  f.resolution = std::vector<int>(size_t(D), n);
  f.size = std::vector<double>(size_t(D), 1.0);
  f.viscosity = 1.0 / re;
  f.boundaries.sides[3].wallVelocity = {1.0, 0.0, 0.0};  // the lid: y_max moves along +x
  return f;
}

struct CoupledRun {
  std::vector<std::vector<double>> species;
  std::vector<float> velocity;
  size_t poolBytes = 0;      // what the fluid's work pool holds after the run
  size_t advectedBytes = 0;  // what the fluid keeps of the velocity it advected through
};

// A Gray-Scott layer in a lid-driven cavity (fluid 24^D, chemicals
// rdCells^D), run with one backend; by hand: the fluid's step, then the ARD's
// through the velocity it advected through, each with its own work vectors.
template <int D>
CoupledRun runCavity(Backend backend, int threads, int steps, double dt, int rdCells, StageTrace* trace = nullptr,
                     bool byHand = false) {
  ThreadLimit limit(threads);
  FluidSolver<D> fluid(cavity<D>(24, 400));
  RDSettings s;
  s.model = "gray-scott";
  s.resolution = std::vector<int>(size_t(D), rdCells);
  s.size = std::vector<double>(size_t(D), 1.0);
  s.boundary = RDBoundary::Neumann;
  s.diffusion = {2e-5 * 4, 1e-5 * 4};
  s.parameters = {0.04, 0.06};
  RDSolver<D> rd(s, *findModel("gray-scott"));
  forEachCell<D>(rd.cells(), [&](const IVec<D>& k, size_t i) {
    bool inside = true;
    for (int a = 0; a < D; ++a) inside = inside && std::abs(k[a] - rdCells / 2) < rdCells / 5;
    rd.field(0)[i] = (inside ? 0.5 : 1.0) + 0.02 * (uniform01(3, 0, i) - 0.5);
    rd.field(1)[i] = (inside ? 0.25 : 0.0) + 0.02 * uniform01(3, 1, i);
  });
  ChemicalDomain<D> d;
  d.cells = rd.cells();
  d.h = rd.h();
  ARDSolver<D> ard(&rd, ChemicalAdvector<D>(d, ChemicalInterpolation::Cubic), CouplingMode::ARD, 50.0);
  if (byHand) {
    fluid.keepAdvectedVelocity(true);  // (read after the fluid's step)
    for (int i = 0; i < steps; ++i) {
      fluid.step(dt);
      ard.step(dt, fluid.advectedVelocity());
    }
  } else {
    CpuCoupledStepper<D> stepper(&fluid, &ard, backend);
    stepper.setTrace(trace);
    for (int i = 0; i < steps; ++i) stepper.step(dt);
  }
  CoupledRun r;
  for (int sp = 0; sp < 2; ++sp) r.species.push_back(rd.field(sp).values());
  for (int a = 0; a < D; ++a) {
    r.velocity.insert(r.velocity.end(), fluid.velocity()[a].values().begin(), fluid.velocity()[a].values().end());
    r.advectedBytes += fluid.advectedVelocity()[a].values().capacity() * sizeof(float);
  }
  r.poolBytes = fluid.workPool()->bytes();
  return r;
}

void expectSameRuns(const CoupledRun& a, const CoupledRun& b) {
  EXPECT_EQ(a.velocity, b.velocity);
  for (int sp = 0; sp < 2; ++sp) EXPECT_EQ(a.species[size_t(sp)], b.species[size_t(sp)]) << "species " << sp;
  double spread = 0;  // the chemicals did move and react
  for (size_t i = 0; i < a.species[1].size(); ++i) spread += std::abs(a.species[1][i] - a.species[1][0]);
  EXPECT_GT(spread, 1.0);
}

}  // namespace

// Serial (nested) and tbb (overlapped in 2D) give the same bits, for 1 and
// 2 threads.
TEST(CpuCoupledStepper, SerialAndTbbAreBitwiseIdentical) {
  const CoupledRun a = runCavity<2>(Backend::Serial, 1, 30, 0.02, 40);
  expectSameRuns(a, runCavity<2>(Backend::TBB, 2, 30, 0.02, 40));
  expectSameRuns(a, runCavity<2>(Backend::TBB, 1, 30, 0.02, 40));
}

// In 3D the ARD step runs nested in the fluid's on the fluid's work vectors:
// the same bits as the two steps one after the other, each with its own.
TEST(CpuCoupledStepper, TheNestedStepIsBitwiseTheTwoStepsInTurn) {
  const CoupledRun a = runCavity<3>(Backend::TBB, 2, 6, 0.02, 32);
  expectSameRuns(a, runCavity<3>(Backend::TBB, 1, 6, 0.02, 32, nullptr, true));
  expectSameRuns(a, runCavity<3>(Backend::Serial, 1, 6, 0.02, 32));
}

// Nested, the ARD step borrows every work vector it needs from the fluid's
// pool without growing it (chemicals on the fluid's grid), and neither step
// keeps the velocity the fluid advected through: the feet are traced first
// and its storage goes back to the pool, the reaction-diffusion solves and
// the carried species fit in what the pressure's solve leaves there.
TEST(CpuCoupledStepper, TheNestedStepNeedsNoMoreWorkMemoryThanTheFluidAlone) {
  const CoupledRun coupled = runCavity<3>(Backend::TBB, 2, 4, 0.02, 24);
  FluidSolver<3> fluid(cavity<3>(24, 400));
  for (int i = 0; i < 4; ++i) fluid.step(0.02);
  size_t advected = 0;
  for (int a = 0; a < 3; ++a) advected += fluid.advectedVelocity()[a].values().capacity();
  EXPECT_EQ(advected, 0u);
  EXPECT_EQ(coupled.advectedBytes, 0u);
  EXPECT_GT(fluid.workPool()->bytes(), 0u);
  EXPECT_EQ(coupled.poolBytes, fluid.workPool()->bytes());
}

// At a time step far beyond the advective CFL limit (lid speed 1, h = 1/24:
// CFL 6) and 50x the RD clock, the coupled layer stays bounded and finite.
TEST(CpuCoupledStepper, LargeTimeStepStaysBounded) {
  const CoupledRun r = runCavity<2>(Backend::TBB, 2, 300, 0.25, 48);
  for (int sp = 0; sp < 2; ++sp)
    for (double v : r.species[size_t(sp)]) {
      ASSERT_TRUE(std::isfinite(v));
      EXPECT_GE(v, -1e-6);
      EXPECT_LE(v, 1.0 + 1e-6);
    }
  for (float v : r.velocity) {
    ASSERT_TRUE(std::isfinite(v));
    EXPECT_LT(std::abs(v), 3.0f);
  }
}

// The trace shows the schedule: with tbb (2D) the ARD step of step n runs
// on another thread while the fluid computes step n + 1; serial nests it
// between the fluid's advection and its diffusion, on one thread.
// 160^2 keeps each stage long (a few ms) against scheduling jitter: at 96^2
// the faster solvers left too short a window on a loaded machine (ctest -j2),
// where 3 to 6 of 12 steps overlapped.
TEST(CpuCoupledStepper, TraceShowsTheOverlap) {
  // Each step's 6 events (4 fluid stages, 2 ARD stages) in the order they began.
  auto steps = [](Backend backend, int* threads) {
    StageTrace trace;
    runCavity<2>(backend, 2, 12, 0.02, 160, &trace);
    std::vector<StageTrace::Event> events = trace.events();
    std::set<int> used;
    for (const auto& e : events) used.insert(e.thread);
    *threads = int(used.size());
    EXPECT_EQ(events.size(), 12u * 6u);
    std::vector<std::vector<StageTrace::Event>> byStep;
    for (size_t i = 0; i + 6 <= events.size(); i += 6) {
      byStep.emplace_back(events.begin() + long(i), events.begin() + long(i + 6));
      std::stable_sort(byStep.back().begin(), byStep.back().end(),
                       [](const auto& x, const auto& y) { return x.begin < y.begin; });
    }
    return byStep;
  };
  int serialThreads = 0, tbbThreads = 0;
  for (const auto& step : steps(Backend::Serial, &serialThreads)) {
    const char* order[6] = {"fluid", "fluid", "ard", "ard", "fluid", "fluid"};
    for (size_t k = 0; k < 6; ++k) {
      EXPECT_EQ(step[k].category, order[k]) << k;
      if (k > 0) {
        EXPECT_GE(step[k].begin, step[k - 1].end) << k;  // one after the other
      }
    }
  }
  EXPECT_EQ(serialThreads, 1);
  if (std::thread::hardware_concurrency() >= 2) {
    int overlapped = 0;
    for (const auto& step : steps(Backend::TBB, &tbbThreads)) {
      double fluid[2] = {1e300, -1e300}, ard[2] = {1e300, -1e300};
      for (const auto& e : step) {
        double* span = e.category == "fluid" ? fluid : ard;
        span[0] = std::min(span[0], e.begin);
        span[1] = std::max(span[1], e.end);
      }
      overlapped += std::max(fluid[0], ard[0]) < std::min(fluid[1], ard[1]) ? 1 : 0;
    }
    EXPECT_GT(overlapped, 6);
    EXPECT_EQ(tbbThreads, 2);
  }
}

// The four-cell AVX2 sampler gives bitwise the scalar loop's fields: random
// velocities whose back-traces leave through every wall, two inflow sides,
// species with random values, and grid sizes that leave partial groups.
template <int D>
void expectWideSamplerIsScalar(const IVec<D>& cells) {
  std::mt19937_64 rng(D);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  MacVelocity<D> u(cells, 1.0 / cells[0], {});
  for (int a = 0; a < D; ++a)
    for (float& v : u[a].values()) v = float(3.0 * U(rng));
  ChemicalDomain<D> d;
  d.cells = cells;
  d.h = 1.0 / cells[0];
  d.inflow[0][0] = true;
  d.inflow[1][1] = true;
  d.inflowValues = {0.7, -0.3};
  const bool wide = useAvx2();
  std::vector<Grid<double, D>> out;
  for (bool narrow : {false, true}) {
    setUseAvx2(wide && !narrow);
    ChemicalAdvector<D> adv(d, ChemicalInterpolation::Linear);
    Grid<double, D> a(cells), b(cells);
    std::mt19937_64 values(11);
    for (size_t i = 0; i < a.size(); ++i) a[i] = U(values), b[i] = U(values);
    for (int s = 0; s < 3; ++s) adv.advect(u, 2.5 * d.h, {&a, &b});
    out.push_back(a);
    out.push_back(b);
  }
  setUseAvx2(wide);
  for (int s = 0; s < 2; ++s)
    EXPECT_EQ(0, std::memcmp(out[size_t(s)].data(), out[size_t(s) + 2].data(), out[0].size() * sizeof(double)))
        << D << "D species " << s;
}

TEST(ChemicalAdvection, WideSamplerIsTheScalarLoopBitwise) {
  expectWideSamplerIsScalar<2>(IVec<2>(37, 29));
  expectWideSamplerIsScalar<3>(IVec<3>(13, 11, 9));
}

// A velocity near float's limit (a run diverging within a step, or a resumed
// state holding one) sends the back-traces to infinity or NaN: every
// sampler keeps its indices inside the grid (boundedCoordinate), so the
// step ends with values from the grid, never a read outside it.
TEST(ChemicalAdvection, AVelocityNearFloatsLimitSamplesInsideTheGrid) {
  const int n = 16;
  for (bool periodic : {false, true})
    for (ChemicalInterpolation interp : {ChemicalInterpolation::Linear, ChemicalInterpolation::Cubic}) {
      MacVelocity<2> u(IVec<2>(n, n), 1.0 / n, {periodic, periodic});
      u[0].fill(3e38f);
      u[1].fill(-3e38f);
      for (int j = 0; j < n; j += 3) u[0](IVec<2>(5, j)) = -3e38f;  // opposite signs meet: inf - inf
      ChemicalDomain<2> d;
      d.cells = IVec<2>(n, n);
      d.h = 1.0 / n;
      d.periodic = {periodic, periodic};
      ChemicalAdvector<2> adv(d, interp);
      Grid<double, 2> g(d.cells);
      for (size_t i = 0; i < g.size(); ++i) g[i] = 0.25 + 0.5 * double(i % 7) / 6.0;
      for (int s = 0; s < 3; ++s) adv.advect(u, 1.0, {&g});
      for (double v : g.values()) {
        ASSERT_TRUE(std::isfinite(v)) << "periodic " << periodic;
        EXPECT_GE(v, 0.25 - 1e-12);
        EXPECT_LE(v, 0.75 + 1e-12);
      }
    }
}
