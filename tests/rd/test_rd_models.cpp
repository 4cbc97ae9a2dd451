// Reaction models and the implicit reaction step: Newton residuals on random
// states, analytic Jacobians against finite differences, the lookup table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "core/simd_dispatch.h"
#include "rd/model_registry.h"
#include "rd/reaction_lut.h"

using namespace morphoflow;

namespace {
std::vector<double> defaults(const ReactionModel& m) {
  std::vector<double> p;
  for (const ParameterInfo& q : m.info().parameters) p.push_back(q.value);
  return p;
}
}  // namespace

TEST(ReactionModels, CatalogueCoversTheSeeds) {
  for (const char* name : {"turing", "turing-sanderson", "gray-scott", "gray-scott-sanderson", "fitzhugh-nagumo",
                           "barkley", "barkley-turbulent", "meinhardt", "brusselator", "gierer-meinhardt",
                           "oregonator", "meinhardt-lateral", "brusselator-coupled", "oregonator-3layer"}) {
    const ReactionModel* m = findModel(name);
    ASSERT_NE(m, nullptr) << name;
    const ModelInfo& in = m->info();
    EXPECT_EQ(in.diffusion.size(), in.species.size()) << name;
    EXPECT_EQ(in.initial.size(), in.species.size()) << name;
    EXPECT_FALSE(in.equations.empty()) << name;
    EXPECT_NE(describeModel(*m).find(in.parameters.front().name), std::string::npos);
  }
  EXPECT_EQ(findModel("grey-scott"), nullptr);
}

// The analytic Jacobian matches central differences of the rates.
TEST(ReactionModels, JacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(7);
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& in = m->info();
    const int n = m->species();
    std::vector<double> p = defaults(*m);
    std::uniform_real_distribution<double> U(in.lutLow + 0.05 * (in.lutHigh - in.lutLow), in.lutHigh);
    for (int trial = 0; trial < 20; ++trial) {
      double x[8], J[64], rp[8], rm[8];
      for (int s = 0; s < n; ++s) x[s] = U(rng);
      m->jacobian(x, p.data(), J);
      for (int t = 0; t < n; ++t) {
        double e = 1e-6 * std::max(1.0, std::abs(x[t])), keep = x[t];
        x[t] = keep + e;
        m->rates(x, p.data(), rp);
        x[t] = keep - e;
        m->rates(x, p.data(), rm);
        x[t] = keep;
        for (int s = 0; s < n; ++s) {
          double fd = (rp[s] - rm[s]) / (2 * e);
          EXPECT_NEAR(J[s * n + t], fd, 1e-5 * std::max(1.0, std::abs(fd)))
              << in.name << " dR" << s << "/dx" << t;
        }
      }
    }
  }
}

// Every model's Newton update solves x - x0 - dt R(x) = 0 to below 1e-10 on
// random states, from small to very large steps.
TEST(ReactionModels, NewtonResidualBelow1e10OnRandomStates) {
  std::mt19937_64 rng(11);
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& in = m->info();
    const int n = m->species();
    std::vector<double> p = defaults(*m);
    std::uniform_real_distribution<double> U(in.lutLow, in.lutHigh);
    int worstIt = 0;
    for (double dt : {1e-3, 1e-2, 0.1, 1.0, 10.0}) {
      for (int trial = 0; trial < 200; ++trial) {
        double x0[8], x[8], r[8];
        for (int s = 0; s < n; ++s) x0[s] = U(rng);
        int it = 0;
        double res = 0;
        bool ok = newtonSolve(*m, x0, p.data(), dt, x, &it, &res);
        worstIt = std::max(worstIt, it);
        ASSERT_TRUE(ok) << in.name << " dt " << dt << " residual " << res;
        // Recompute the residual independently of the solver's bookkeeping.
        // A clamped species held at 0 satisfies the complementarity form
        // instead: its unconstrained update would push it below 0.
        m->rates(x, p.data(), r);
        for (int s = 0; s < n; ++s) {
          double f = x[s] - x0[s] - dt * r[s];
          bool held = x[s] == 0.0 && std::count(in.clamped.begin(), in.clamped.end(), s);
          if (held)
            EXPECT_GT(f, -1e-10) << in.name << " dt " << dt;
          else
            EXPECT_LT(std::abs(f), 1e-10) << in.name << " dt " << dt;
        }
      }
    }
    EXPECT_LE(worstIt, 5000) << in.name;  // restarts included: never a runaway loop
  }
}

// The tabulated implicit step agrees with Newton inside the table.
TEST(ReactionModels, LookupTableMatchesNewton) {
  const ReactionModel& m = *findModel("gray-scott");
  std::vector<double> p = defaults(m);
  const double dt = 1.0;
  ReactionLUT lut;
  ASSERT_TRUE(lut.build(m, p.data(), dt, 0.0, 1.0, 512));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    double x0[2] = {U(rng), U(rng)}, a[2], b[2];
    ASSERT_TRUE(lut.lookup(x0, a));
    ASSERT_TRUE(newtonSolve(m, x0, p.data(), dt, b, nullptr, nullptr));
    worst = std::max({worst, std::abs(a[0] - b[0]), std::abs(a[1] - b[1])});
  }
  EXPECT_LT(worst, 1e-4);  // bilinear error ~ (table spacing)^2 |x''| / 8
  double outside[2] = {1.5, 0.2}, y[2];
  EXPECT_FALSE(lut.lookup(outside, y));
  // Round-off around the table's edge (a diffusion solve leaves v = -1e-17
  // where it was 0) still reads the table, as close to Newton as inside.
  for (double edge : {-1e-17, 1.0 + 1e-15}) {
    double x0[2] = {0.6, edge}, a[2], b[2];
    ASSERT_TRUE(lut.lookup(x0, a)) << edge;
    ASSERT_TRUE(newtonSolve(m, x0, p.data(), dt, b, nullptr, nullptr));
    EXPECT_LT(std::max(std::abs(a[0] - b[0]), std::abs(a[1] - b[1])), 1e-4) << edge;
  }
  double beyond[2] = {0.6, -1e-3};
  EXPECT_FALSE(lut.lookup(beyond, y));
  EXPECT_FALSE(ReactionLUT().build(*findModel("meinhardt-lateral"), p.data(), dt, 0, 1, 16));
}

// The implicit step four cells at a time (AVX2 lanes, rd/newton_batch.h)
// gives every cell bitwise the scalar code's result and the same statistics,
// for every model, over states inside and beyond the model's range (clamped
// species pushed below 0, stiff cubic kinetics at large dt: the cells the
// batch hands back to the scalar code), a NaN cell, and a row length that
// leaves a partial group.
TEST(ReactionModels, BatchedNewtonIsTheScalarNewtonBitwise) {
  const bool wide = useAvx2();
  std::mt19937_64 rng(5);
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& in = m->info();
    const int n = m->species();
    ParameterValues pv;
    pv.constant = defaults(*m);
    pv.field.assign(pv.constant.size(), nullptr);
    const double span = in.lutHigh - in.lutLow;
    std::uniform_real_distribution<double> U(in.lutLow - 0.2 * span, in.lutHigh + 0.2 * span);
    const size_t cells = 1003;
    std::vector<std::vector<double>> start(size_t(n), std::vector<double>(cells, 0.0));
    for (auto& s : start)
      for (double& v : s) v = U(rng);
    start[0][17] = NAN;
    for (double dt : {1e-3, 0.1, 1.0, 10.0, 100.0}) {
      std::vector<std::vector<double>> got[2] = {start, start};
      NewtonStats stats[2];
      for (int k = 0; k < 2; ++k) {
        setUseAvx2(k == 0 && wide);
        double* xs[ReactionModel::kMaxSpecies];
        for (int s = 0; s < n; ++s) xs[s] = got[k][size_t(s)].data();
        stats[k] = m->implicitUpdate(xs, pv, dt, 0, cells);
      }
      setUseAvx2(wide);
      for (int s = 0; s < n; ++s)
        EXPECT_EQ(0, std::memcmp(got[0][size_t(s)].data(), got[1][size_t(s)].data(), cells * sizeof(double)))
            << in.name << " dt " << dt << " species " << s;
      EXPECT_EQ(stats[0].cells, long(cells));
      EXPECT_EQ(stats[0].cells, stats[1].cells) << in.name;
      EXPECT_EQ(stats[0].failures, stats[1].failures) << in.name << " dt " << dt;
      EXPECT_EQ(stats[0].maxIterations, stats[1].maxIterations) << in.name << " dt " << dt;
      EXPECT_EQ(stats[0].maxResidual, stats[1].maxResidual) << in.name << " dt " << dt;
    }
  }
}
