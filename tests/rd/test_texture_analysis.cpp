// Seed 003: the variogram against closed forms, REG ordering regular above
// random textures, and the texton random walk's move probabilities (eq. 6),
// diffusion (mean square displacement) and lifetimes.
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "rd/texton_walk.h"
#include "rd/variogram.h"

using namespace morphoflow;

TEST(Variogram, SinusoidMatchesTheClosedForm) {
  // t = A sin(2 pi x / lambda): V(d, 0) / var = 2 (1 - cos(2 pi d / lambda)),
  // V(0, d) = 0; REG = 4 at d = lambda / 2.
  const int nx = 96, ny = 40, lambda = 16;
  std::vector<double> t(size_t(nx * ny));
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) t[size_t(y * nx + x)] = 3.0 * std::sin(2 * M_PI * x / lambda) + 7.0;
  Variogram v = variogram(t, nx, ny, {.maxLag = 24, .periodic = true});
  EXPECT_NEAR(v.variance, 4.5, 1e-12);
  for (int d = 1; d <= 24; ++d) {
    const double expect = 2.0 * (1.0 - std::cos(2 * M_PI * d / lambda));
    EXPECT_NEAR(v.v[size_t(d - 1)][0], expect, 1e-12) << d;
    EXPECT_NEAR(v.v[size_t(d - 1)][1], 0.0, 1e-12) << d;
    EXPECT_NEAR(v.v[size_t(d - 1)][2], expect, 1e-12) << d;  // diagonals see the same x shift
    EXPECT_NEAR(v.v[size_t(d - 1)][3], expect, 1e-12) << d;
  }
  EXPECT_NEAR(v.reg, 4.0, 1e-12);
  EXPECT_EQ(v.regLag, lambda / 2);
  // Interior pairs only (no wrap): the same curve up to end effects.
  Variogram w = variogram(t, nx, ny, {.maxLag = 24});
  for (int d = 1; d <= 24; ++d)
    EXPECT_NEAR(w.v[size_t(d - 1)][0], 2.0 * (1.0 - std::cos(2 * M_PI * d / lambda)), 0.25) << d;
}

TEST(Variogram, CheckerboardAndConstant) {
  const int n = 32;
  std::vector<double> t(size_t(n * n)), c(size_t(n * n), 5.0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) t[size_t(y * n + x)] = (x + y) % 2 ? 1.0 : -1.0;
  Variogram v = variogram(t, n, n, {.maxLag = 4});
  // (t - t')^2 = 4 between opposite colours, variance 1.
  EXPECT_DOUBLE_EQ(v.v[0][0], 4.0);
  EXPECT_DOUBLE_EQ(v.v[0][1], 4.0);
  EXPECT_DOUBLE_EQ(v.v[0][2], 0.0);  // diagonal neighbours share a colour
  EXPECT_DOUBLE_EQ(v.v[1][0], 0.0);
  EXPECT_DOUBLE_EQ(v.reg, 4.0);
  Variogram k = variogram(c, n, n);
  EXPECT_EQ(k.reg, 0.0);
}

TEST(Variogram, WhiteNoiseIsTwoAtEveryLag) {
  // Independent values: E[(t - t')^2] = 2 var exactly in expectation.
  const int n = 256;
  std::vector<double> t(size_t(n * n));
  for (size_t i = 0; i < t.size(); ++i) t[i] = uniform01(7, 0, i);
  Variogram v = variogram(t, n, n, {.maxLag = 8});
  for (const auto& lag : v.v)
    for (double x : lag) EXPECT_NEAR(x, 2.0, 0.05);
}

TEST(TextonWalk, MoveFrequenciesFollowEquationSix) {
  TextonWalkSettings s;
  s.width = s.height = 1001;
  s.lifetime = 4.0;
  s.p = 0.3;
  s.q = 0.5;
  s.stepSize = 1;
  const int trials = 200000;
  // Outcomes: expired, centre, UL, LL, UR, LR.
  double count[6] = {};
  for (int e = 0; e < trials; ++e) {
    std::array<int, 2> at = {500, 500};
    if (!textonStep(s, uint64_t(e), 0, &at)) {
      ++count[0];
      continue;
    }
    const int dx = at[0] - 500, dy = at[1] - 500;
    int k = dx == 0 ? 1 : dx < 0 ? (dy > 0 ? 2 : 3) : (dy > 0 ? 4 : 5);
    ++count[k];
  }
  const double live = 1.0 - 1.0 / s.lifetime;
  const double expect[6] = {1.0 / s.lifetime, live * (1 - s.p - s.q), 0.5 * live * s.q, 0.5 * live * s.q,
                            0.5 * live * s.p, 0.5 * live * s.p};
  for (int k = 0; k < 6; ++k) {
    const double sigma = std::sqrt(expect[k] * (1 - expect[k]) / trials);
    EXPECT_NEAR(count[k] / trials, expect[k], 5 * sigma) << "outcome " << k;
  }
}

TEST(TextonWalk, UnbiasedWalkDiffusesAtTheStepSize) {
  // p = q = 1/2: each step moves +-s on both axes, so <|dx|^2> = 2 s^2 n.
  TextonWalkSettings s;
  s.width = s.height = 4001;
  s.elements = 4000;
  s.steps = 100;
  s.stepSize = 2;
  std::vector<std::array<int, 2>> end = textonWalk(s);
  ASSERT_EQ(end.size(), size_t(s.elements));  // no expiry
  double msd = 0.0, mx = 0.0;
  for (const auto& p : end) {
    const double dx = p[0] - 2000, dy = p[1] - 2000;
    msd += dx * dx + dy * dy;
    mx += dx;
  }
  msd /= double(end.size());
  mx /= double(end.size());
  const double expect = 2.0 * s.stepSize * s.stepSize * s.steps;  // 800
  EXPECT_NEAR(msd, expect, 0.05 * expect);
  EXPECT_NEAR(mx, 0.0, 5.0 * std::sqrt(expect / 2 / s.elements));
}

TEST(TextonWalk, LifetimeThinsThePopulationGeometrically) {
  TextonWalkSettings s;
  s.elements = 20000;
  s.steps = 10;
  s.lifetime = 20.0;
  const double expect = s.elements * std::pow(1.0 - 1.0 / s.lifetime, s.steps);
  const double got = double(textonWalk(s).size());
  EXPECT_NEAR(got, expect, 5 * std::sqrt(expect * (1 - expect / s.elements)));
}

TEST(TextonWalk, BoundariesHoldElementsInside) {
  TextonWalkSettings s;
  s.width = 16;
  s.height = 9;
  s.elements = 300;
  s.steps = 500;
  s.stepSize = 3;
  s.start = TextonStart::Uniform;
  for (const auto& p : textonWalk(s)) {
    EXPECT_GE(p[0], 0);
    EXPECT_LT(p[0], 16);
    EXPECT_GE(p[1], 0);
    EXPECT_LT(p[1], 9);
  }
  s.p = 0.7;
  s.q = 0.4;
  EXPECT_THROW(checkTextonWalk(s), std::invalid_argument);
}

TEST(TextonWalk, RegularPlacementScoresHigherRegThanARandomWalk) {
  // Seed 003: textures of varying regularity; walking the regular lattice
  // for longer makes the texture less regular.
  TextonWalkSettings s;
  s.width = s.height = 128;
  s.elements = 64;
  s.radius = 3.0;
  s.start = TextonStart::Regular;
  s.steps = 0;
  const double regular = variogram(renderTextons(textonWalk(s), s), 128, 128, {.maxLag = 32}).reg;
  s.steps = 400;
  s.stepSize = 1;
  const double walked = variogram(renderTextons(textonWalk(s), s), 128, 128, {.maxLag = 32}).reg;
  EXPECT_GT(regular, walked + 0.2) << regular << " vs " << walked;
  EXPECT_LE(regular, 4.0);
}
