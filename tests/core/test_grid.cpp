#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>

#include "core/grid.h"
#include "core/parallel.h"
#include "core/sampling.h"

using namespace morphoflow;

TEST(Grid, IndexAndCoordAreInverse3D) {
  Grid<float, 3> g(IVec<3>(5, 4, 3));
  ASSERT_EQ(g.size(), 60u);
  for (size_t i = 0; i < g.size(); ++i) EXPECT_EQ(g.index(g.coord(i)), i);
  EXPECT_EQ(g.stride(0), 1u);
  EXPECT_EQ(g.stride(1), 5u);
  EXPECT_EQ(g.stride(2), 20u);
}

TEST(Sampling, BilinearReproducesLinearFunctionsExactly) {
  // Linear functions are reproduced exactly by bilinear interpolation.
  IVec<2> n(8, 6);
  Grid<float, 2> g(n);
  auto layout = Layout<2>::cellCentred(0.125, n, {false, false});
  for (size_t i = 0; i < g.size(); ++i) {
    Vec<2> x = layout.toWorld(g.coord(i));
    g[i] = float(2.0 * x[0] - 3.0 * x[1] + 1.0);
  }
  for (double x : {0.1, 0.33, 0.5, 0.9}) {
    for (double y : {0.07, 0.4, 0.68}) {
      float lo, hi;
      float v = sampleLinear(g, layout, Vec<2>(x, y), &lo, &hi);
      EXPECT_NEAR(v, 2.0 * x - 3.0 * y + 1.0, 1e-5);
      EXPECT_LE(lo, v + 1e-6f);
      EXPECT_GE(hi, v - 1e-6f);
    }
  }
}

TEST(Sampling, PeriodicAxisWrapsAround) {
  IVec<2> n(4, 4);
  Grid<float, 2> g(n);
  auto layout = Layout<2>::cellCentred(1.0, n, {true, false});
  for (size_t i = 0; i < g.size(); ++i) g[i] = float(g.coord(i)[0]);
  // Halfway between cell 3 (x = 3.5) and cell 0 wrapped (x = 4.5).
  EXPECT_NEAR(sampleLinear(g, layout, Vec<2>(4.0, 1.5)), 1.5, 1e-6);
  EXPECT_NEAR(sampleLinear(g, layout, Vec<2>(-0.5 + 4.0, 1.5)), 3.0, 1e-6);
}

TEST(Parallel, DeterministicSumIndependentOfThreadCount) {
  const size_t n = 1'000'003;
  auto f = [](size_t i) { return 1.0 / double(i + 1); };
  double a, b;
  {
    ThreadLimit one(1);
    a = deterministicSum(n, f);
  }
  {
    ThreadLimit two(2);
    b = deterministicSum(n, f);
  }
  EXPECT_EQ(a, b);  // bitwise
}

// parallelTasks runs each piece once, and a thread that waits inside one
// piece's loop never starts another piece: what a piece keeps
// thread-local (as rowScratch) is still its own when the loop returns.
TEST(Parallel, TasksRunOnceEachAndKeepTheirThreadLocalScratch) {
  ThreadLimit two(2);
  constexpr size_t kPieces = 64;
  std::array<std::atomic<int>, kPieces> runs{};
  std::atomic<int> taken{0};  // a piece that found another's value in its scratch
  parallelTasks(kPieces, [&](size_t i) {
    thread_local size_t owner = SIZE_MAX;
    for (int round = 0; round < 20; ++round) {
      owner = i;
      parallelFor(
          64,
          [&](size_t k) {  // (chunks of uneven length: a thread left waiting on another's)
            volatile double x = 0.0;
            for (size_t j = 0; j < 200 * ((k + i) % 7 + 1); ++j) x = x + double(j);
          },
          1);
      if (owner != i) ++taken;
    }
    ++runs[i];
  });
  for (size_t i = 0; i < kPieces; ++i) EXPECT_EQ(runs[i].load(), 1) << "piece " << i;
  EXPECT_EQ(taken.load(), 0);
}
