// The reaction-diffusion integrators: unconditional stability, first-order
// convergence of the split, travelling-front speed, linear Turing
// instability against the discrete dispersion relation, seamless tiling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>

#include "core/parallel.h"
#include "core/random.h"
#include "rd/coarse_to_fine.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

using namespace morphoflow;

namespace {

RDSettings grid2(const std::string& model, int nx, int ny, double h) {
  RDSettings s;
  s.model = model;
  s.resolution = {nx, ny};
  s.size = {nx * h, ny * h};
  return s;
}

void addNoise(RDSolver<2>& rd, double amplitude, uint64_t seed) {
  for (int s = 0; s < rd.species(); ++s) {
    Grid<double, 2>& g = rd.field(s);
    for (size_t i = 0; i < g.size(); ++i) g[i] += amplitude * (2.0 * uniform01(seed, uint64_t(s), i) - 1.0);
  }
}

double maxAbs(const RDSolver<2>& rd) {
  double m = 0;
  for (int s = 0; s < rd.species(); ++s)
    for (size_t i = 0; i < rd.field(s).size(); ++i) {
      double v = rd.field(s)[i];
      if (!std::isfinite(v)) return INFINITY;
      m = std::max(m, std::abs(v));
    }
  return m;
}

}  // namespace

// Kim & Lin's split at 100x the explicit diffusion limit stays bounded for
// 10,000 steps, for every model.
class EveryModel : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryModel, KimLinUnconditionallyStable) {
  const ReactionModel* m = findModel(GetParam());
  ASSERT_NE(m, nullptr);
  RDSettings s = grid2(m->info().name, 16, 16, 1.0);
  RDSolver<2> rd(s, *m);
  addNoise(rd, 0.01 * (m->info().lutHigh - m->info().lutLow), 5);
  const double dt = 100.0 * rd.explicitDiffusionLimit();
  double start = maxAbs(rd), worst = 0;
  for (int step = 0; step < 10000; ++step) {
    rd.step(dt);
    if (step % 500 == 0 || step == 9999) worst = std::max(worst, maxAbs(rd));
    ASSERT_TRUE(rd.lastStats().diffusion.converged);
  }
  EXPECT_TRUE(std::isfinite(worst));
  // Bounded: within a modest factor of the model's natural range.
  double range = std::max({1.0, std::abs(m->info().lutHigh), std::abs(m->info().lutLow), start});
  EXPECT_LT(worst, 20.0 * range) << "dt " << dt;
}

INSTANTIATE_TEST_SUITE_P(RDSolver, EveryModel, ::testing::ValuesIn(modelNames()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string n = i.param;
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

// Explicit Euler at 100x its limit blows up: the stability above is the
// scheme's, not the problem's.
TEST(RDSolver, ExplicitEulerBeyondItsLimitDiverges) {
  RDSettings s = grid2("gray-scott", 16, 16, 1.0);
  s.diffusion = {0.2, 0.1};
  s.integrator = RDIntegrator::ExplicitEuler;
  RDSolver<2> rd(s, *findModel("gray-scott"));
  addNoise(rd, 0.1, 9);
  const double dt = 4.0 * rd.explicitDiffusionLimit();
  for (int i = 0; i < 200; ++i) rd.step(dt);
  EXPECT_FALSE(maxAbs(rd) < 10.0);
}

// The implicit split converges to the reference solution at first order in dt.
TEST(RDSolver, KimLinConvergesAtFirstOrder) {
  const ReactionModel& m = *findModel("gray-scott");
  auto run = [&](RDIntegrator integ, double dt, double T) {
    RDSettings s = grid2("gray-scott", 32, 32, 1.0 / 32);
    s.diffusion = {2e-3, 1e-3};
    s.parameters = {0.04, 0.06};
    s.integrator = integ;
    s.tolerance = 1e-12;
    RDSolver<2> rd(s, m);
    forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
      double x = (k[0] + 0.5) / 32, y = (k[1] + 0.5) / 32;
      double bump = std::exp(-40 * ((x - 0.5) * (x - 0.5) + (y - 0.45) * (y - 0.45)));
      rd.field(0)[i] = 1.0 - 0.5 * bump;
      rd.field(1)[i] = 0.25 * bump;
    });
    long n = std::lround(T / dt);
    for (long i = 0; i < n; ++i) rd.step(dt);
    return std::vector<double>(rd.field(1).values());
  };
  const double T = 4.0;
  std::vector<double> ref = run(RDIntegrator::ExplicitEuler, 1.0 / 1024, T);
  double err[3];
  double dts[3] = {0.2, 0.1, 0.05};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v = run(RDIntegrator::KimLin, dts[k], T);
    double e = 0;
    for (size_t i = 0; i < v.size(); ++i) e = std::max(e, std::abs(v[i] - ref[i]));
    err[k] = e;
  }
  double p1 = std::log2(err[0] / err[1]), p2 = std::log2(err[1] / err[2]);
  EXPECT_NEAR(p1, 1.0, 0.2) << err[0] << " " << err[1] << " " << err[2];
  EXPECT_NEAR(p2, 1.0, 0.15) << err[0] << " " << err[1] << " " << err[2];
}

// A planar Barkley front with B frozen is a Nagumo front,
//   A_t = D A_xx + k A (1 - A)(A - alpha),  k = 1/eps, alpha = (B + b)/a,
// moving at c = sqrt(2 D k) (1/2 - alpha).
TEST(RDSolver, NagumoFrontMovesAtTheAnalyticSpeed) {
  const ReactionModel& m = *findModel("barkley");
  const double a = 1.0, b = 0.1, eps = 1.0, D = 1.0, h = 0.1;
  RDSettings s = grid2("barkley", 1000, 2, h);
  s.parameters = {a, b, eps};
  s.diffusion = {D, 0.0};
  s.boundary = RDBoundary::Neumann;
  s.frozen = {1};
  s.integrator = RDIntegrator::CrankNicolson;
  RDSolver<2> rd(s, m);
  forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
    rd.field(0)[i] = k[0] < 150 ? 1.0 : 0.0;
    rd.field(1)[i] = 0.0;
  });
  auto front = [&] {  // where A crosses 1/2 along row 0
    const Grid<double, 2>& A = rd.field(0);
    for (int x = 0; x + 1 < 1000; ++x)
      if (A[size_t(x)] >= 0.5 && A[size_t(x) + 1] < 0.5)
        return h * (x + 0.5 + (A[size_t(x)] - 0.5) / (A[size_t(x)] - A[size_t(x) + 1]));
    return -1.0;
  };
  const double dt = 0.002;
  for (int i = 0; i < 5000; ++i) rd.step(dt);  // t = 10: the front has its shape
  double x1 = front(), t1 = rd.time();
  for (int i = 0; i < 15000; ++i) rd.step(dt);  // t = 40
  double x2 = front(), t2 = rd.time();
  double c = (x2 - x1) / (t2 - t1);
  double alpha = b / a, analytic = std::sqrt(2.0 * D / eps) * (0.5 - alpha);
  EXPECT_NEAR(c, analytic, 0.02 * analytic) << "measured " << c << " analytic " << analytic;
}

namespace {

// Largest real part of the eigenvalues of J - lambda diag(d) (2 x 2).
double growthRate(const double* J, const std::vector<double>& d, double lambda) {
  double a = J[0] - lambda * d[0], b = J[1], c = J[2], e = J[3] - lambda * d[1];
  double tr = a + e, det = a * e - b * c, disc = tr * tr / 4 - det;
  return disc >= 0 ? tr / 2 + std::sqrt(disc) : tr / 2;
}

struct TuringCase {
  std::string model;
  std::vector<double> params, diffusion, steady;
};

// Runs from small noise along x (uniform along y) and returns the dominant
// Fourier mode of species 0 and the predicted fastest-growing mode (0 if no
// mode grows).
void turingRun(const TuringCase& tc, double h, int n, double T, double dt, int* observed, int* predicted,
               double* amplification) {
  const ReactionModel& m = *findModel(tc.model);
  RDSettings s = grid2(tc.model, n, 4, h);
  s.parameters = tc.params;
  s.diffusion = tc.diffusion;
  s.tolerance = 1e-12;
  RDSolver<2> rd(s, m);
  double J[4];
  m.jacobian(tc.steady.data(), tc.params.data(), J);
  double best = 0;
  *predicted = 0;
  for (int q = 1; q <= n / 2; ++q) {
    double lambda = 4.0 / (h * h) * std::pow(std::sin(M_PI * q / n), 2);  // -eigenvalue of the discrete Laplacian
    double sigma = growthRate(J, tc.diffusion, lambda);
    if (sigma > best) {
      best = sigma;
      *predicted = q;
    }
  }
  for (int sp = 0; sp < 2; ++sp)
    forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
      rd.field(sp)[i] = tc.steady[size_t(sp)] + 1e-6 * (2.0 * uniform01(17, uint64_t(sp), uint64_t(k[0])) - 1.0);
    });
  auto spectrum = [&](std::vector<double>* p) {
    p->assign(size_t(n / 2 + 1), 0.0);
    const Grid<double, 2>& u = rd.field(0);
    for (int q = 1; q <= n / 2; ++q) {
      std::complex<double> c = 0;
      for (int x = 0; x < n; ++x) c += u[size_t(x)] * std::polar(1.0, -2 * M_PI * q * x / n);
      (*p)[size_t(q)] = std::abs(c);
    }
  };
  std::vector<double> p0, p1;
  spectrum(&p0);
  for (long i = 0; i < std::lround(T / dt); ++i) rd.step(dt);
  spectrum(&p1);
  *observed = int(std::max_element(p1.begin() + 1, p1.end()) - p1.begin());
  double a0 = *std::max_element(p0.begin() + 1, p0.end()), a1 = *std::max_element(p1.begin() + 1, p1.end());
  *amplification = a1 / a0;
}

}  // namespace

TEST(RDSolver, TuringInstabilityPicksTheFastestGrowingMode) {
  // Brusselator: Turing-unstable iff d_a/d_b < ((sqrt(beta) - 1)/alpha)^2 = 4/9.
  TuringCase bru{"brusselator", {1.0, 3.0, 9.0}, {2.0, 8.0}, {3.0, 3.0}};
  int obs, pred;
  double amp;
  turingRun(bru, 0.5, 128, 30.0, 0.01, &obs, &pred, &amp);
  ASSERT_GT(pred, 0);
  EXPECT_GT(amp, 100.0) << "the unstable band must grow";
  EXPECT_LE(std::abs(obs - pred), 1) << "observed mode " << obs << " predicted " << pred;
  // Gray-Scott on its upper steady state, F = k = 0.05 (v the activator).
  const double F = 0.05, k = 0.05, v = (F + std::sqrt(F * F - 4 * F * (F + k) * (F + k))) / (2 * (F + k));
  TuringCase gs{"gray-scott", {F, k}, {1.0, 0.1}, {(F + k) / v, v}};
  turingRun(gs, 1.0, 128, 600.0, 0.5, &obs, &pred, &amp);
  ASSERT_GT(pred, 0);
  EXPECT_GT(amp, 100.0);
  EXPECT_LE(std::abs(obs - pred), 1) << "observed mode " << obs << " predicted " << pred;
}

TEST(RDSolver, BelowTheTuringThresholdPerturbationsDecay) {
  int obs, pred;
  double amp;
  TuringCase bru{"brusselator", {1.0, 3.0, 9.0}, {2.0, 4.0}, {3.0, 3.0}};  // d_a/d_b = 1/2 > 4/9
  turingRun(bru, 0.5, 128, 30.0, 0.01, &obs, &pred, &amp);
  EXPECT_EQ(pred, 0);
  EXPECT_LT(amp, 1.0);
  const double F = 0.05, k = 0.05, v = (F + std::sqrt(F * F - 4 * F * (F + k) * (F + k))) / (2 * (F + k));
  TuringCase gs{"gray-scott", {F, k}, {0.4, 0.1}, {(F + k) / v, v}};  // ratio 4 < threshold
  turingRun(gs, 1.0, 128, 600.0, 0.5, &obs, &pred, &amp);
  EXPECT_EQ(pred, 0);
  EXPECT_LT(amp, 1.0);
}

// A periodic pattern tiles: differences across the wrap look like
// differences anywhere else.
TEST(RDSolver, PeriodicPatternsTileSeamlessly) {
  const ReactionModel& m = *findModel("gray-scott");
  RDSettings s = grid2("gray-scott", 96, 96, 2.5 / 96);
  s.parameters = {0.035, 0.065};
  RDSolver<2> rd(s, m);
  forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
    bool centre = std::abs(k[0] - 10) < 8 && std::abs(k[1] - 85) < 8;  // near the corner: the pattern crosses the wrap
    rd.field(0)[i] = centre ? 0.5 : 1.0;
    rd.field(1)[i] = centre ? 0.25 : 0.0;
  });
  addNoise(rd, 0.01, 3);
  for (int i = 0; i < 3000; ++i) rd.step(1.0);
  const Grid<double, 2>& v = rd.field(1);
  double seamX = 0, seamY = 0, inner = 0;
  for (int j = 0; j < 96; ++j) {
    seamX += std::abs(v(IVec<2>(0, j)) - v(IVec<2>(95, j)));
    seamY += std::abs(v(IVec<2>(j, 0)) - v(IVec<2>(j, 95)));
    for (int i = 0; i < 95; ++i) inner += std::abs(v(IVec<2>(i, j)) - v(IVec<2>(i + 1, j)));
  }
  inner /= 95.0;
  ASSERT_GT(inner, 1e-3) << "a pattern must have formed";
  EXPECT_LT(seamX, 1.5 * inner);
  EXPECT_LT(seamY, 1.5 * inner);
}

// Zero-flux boundaries with pure diffusion conserve each species' mass.
TEST(RDSolver, NeumannDiffusionConservesMass) {
  RDSettings s = grid2("gray-scott", 40, 30, 1.0);
  s.boundary = RDBoundary::Neumann;
  s.diffusion = {3.0, 0.5};
  s.parameters = {0.0, 0.0};  // F = k = 0: no reaction on v = 0
  s.tolerance = 1e-12;
  RDSolver<2> rd(s, *findModel("gray-scott"));
  forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) { rd.field(0)[i] = k[0] < 10 ? 2.0 : 0.5; });
  auto mass = [&] {
    double sum = 0;
    for (double x : rd.field(0).values()) sum += x;
    return sum;
  };
  double m0 = mass();
  for (int i = 0; i < 50; ++i) rd.step(5.0);
  EXPECT_NEAR(mass(), m0, 1e-8 * m0);
}

// Prolongation (coarse-to-fine, seed 002): exact on linear fields away from
// the edges, and mean-preserving on periodic grids.
TEST(CoarseToFine, ProlongationIsLinearExactAndConservative) {
  Grid<double, 2> coarse(IVec<2>(8, 6)), fine(IVec<2>(16, 12));
  auto linear = [](double x, double y) { return 2.0 + 0.5 * x - 0.25 * y; };
  forEachCell<2>(coarse.dims(),
                 [&](const IVec<2>& k, size_t i) { coarse[i] = linear(2 * (k[0] + 0.5), 2 * (k[1] + 0.5)); });
  prolongate<2>(coarse, &fine, false);
  for (int j = 1; j < 11; ++j)
    for (int i = 1; i < 15; ++i) EXPECT_NEAR(fine(IVec<2>(i, j)), linear(i + 0.5, j + 0.5), 1e-12);
  Grid<double, 3> c3(IVec<3>(4, 6, 8)), f3(IVec<3>(8, 12, 16));
  double sumC = 0, sumF = 0;
  for (size_t i = 0; i < c3.size(); ++i) sumC += c3[i] = uniform01(5, 0, i);
  prolongate<3>(c3, &f3, true);
  for (size_t i = 0; i < f3.size(); ++i) sumF += f3[i];
  EXPECT_NEAR(sumF / double(f3.size()), sumC / double(c3.size()), 1e-12);
}

// Growing a Turing pattern on a 2x coarser grid first (same domain, twice the
// cell size) and finishing on the fine grid reaches the saturated pattern of
// the fine-only run, with the same dominant wavelength, after T/4 on the fine
// grid (3T/4 on the coarse one, at a quarter of the cost per step); the
// fine-only run has then barely started.
TEST(CoarseToFine, CoarseStartReachesTheFinePatternSooner) {
  const ReactionModel& m = *findModel("brusselator");
  const int n = 128;
  const double h = 0.5, dt = 0.05, T = 24.0;  // the pattern saturates by t = 30 from 1e-4 noise
  auto make = [&](int cells, double cell) {
    RDSettings s = grid2("brusselator", cells, cells / 32, cell);
    s.parameters = {1.0, 3.0, 9.0};
    s.diffusion = {2.0, 8.0};
    return s;
  };
  auto seed = [&](RDSolver<2>& rd) {
    forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
      for (int sp = 0; sp < 2; ++sp)
        rd.field(sp)[i] = 3.0 + 1e-4 * (2.0 * uniform01(17, uint64_t(sp), uint64_t(k[0] * n / rd.cells()[0])) - 1.0);
    });
  };
  auto steps = [&](RDSolver<2>& rd, double t) {
    for (long i = 0; i < std::lround(t / dt); ++i) rd.step(dt);
  };
  // Amplitude and dominant mode of species a along x.
  auto analyse = [&](const RDSolver<2>& rd, double* amp) {
    int best = 0;
    *amp = 0;
    for (int q = 1; q <= n / 2; ++q) {
      std::complex<double> c = 0;
      for (int x = 0; x < n; ++x) c += rd.field(0)[size_t(x)] * std::polar(1.0, -2 * M_PI * q * x / n);
      if (std::abs(c) > *amp) *amp = std::abs(c), best = q;
    }
    return best;
  };
  RDSolver<2> fine(make(n, h), m);
  seed(fine);
  steps(fine, T / 4);
  double ampQuarter, ampFull, ampC2F;
  analyse(fine, &ampQuarter);
  steps(fine, 60.0 - T / 4);  // saturated
  const int modeFull = analyse(fine, &ampFull);

  RDSolver<2> coarse(make(n / 2, 2 * h), m);
  seed(coarse);
  steps(coarse, 3 * T / 4);
  RDSolver<2> finish(make(n, h), m);
  for (int sp = 0; sp < 2; ++sp) prolongate<2>(coarse.field(sp), &finish.field(sp), true);
  steps(finish, T / 4);
  const int modeC2F = analyse(finish, &ampC2F);

  EXPECT_LT(ampQuarter, 0.1 * ampFull) << "the fine-only run must still be growing after T/4";
  EXPECT_GT(ampC2F, 0.7 * ampFull) << ampC2F << " vs " << ampFull;
  EXPECT_LE(std::abs(modeC2F - modeFull), 1) << modeC2F << " vs " << modeFull;
}
