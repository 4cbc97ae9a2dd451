// Kim & Lin's cosine-lobe anisotropy (seed 001 eq. 14-17): the polar
// functions of eq. 15 and 16, the lobe a gradient direction selects (exact
// decay of a discrete Fourier mode at that lobe's rate, rotation by theta0,
// 3D), mass conservation and energy decay, and the stretched Gray-Scott
// patterns of the paper's fig. 4.
#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "core/random.h"
#include "rd/cosine_lobe.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"
#include "tests/rd/rd_test_support.h"

using namespace morphoflow;

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

CosineLobeSpec lobes(std::vector<double> speeds, bool witkinKass = false) {
  CosineLobeSpec s;
  s.speeds = std::move(speeds);
  s.witkinKass = witkinKass;
  return s;
}

// a's mean over the circle by the midpoint rule.
double quadratureMean(const CosineLobeSpec& s) {
  const int n = 1 << 16;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += lobeDiffusivity(s, kTwoPi * (i + 0.5) / n);
  return sum / n;
}

}  // namespace

TEST(CosineLobes, Equation16) {
  const CosineLobeSpec s = lobes({1.0, 0.25, 2.0, 0.5, 3.0});
  const int j = 5;
  for (int n = 0; n < j; ++n) {
    const double centre = kTwoPi * n / j, edge = centre + M_PI / j;
    EXPECT_NEAR(lobeDiffusivity(s, centre), s.speeds[size_t(n)], 1e-14) << "lobe " << n + 1;
    EXPECT_NEAR(lobeDiffusivity(s, centre + kTwoPi), s.speeds[size_t(n)], 1e-12) << "2 pi periodic";
    EXPECT_NEAR(lobeDiffusivity(s, centre - 3 * kTwoPi), s.speeds[size_t(n)], 1e-12) << "2 pi periodic";
    // Zero at both sides of a slice edge: a is continuous though the lobes differ.
    EXPECT_NEAR(lobeDiffusivity(s, edge - 1e-7), 0.0, 1e-12);
    EXPECT_NEAR(lobeDiffusivity(s, edge + 1e-7), 0.0, 1e-12);
    // Within a slice the lobe keeps its own speed: (1 + cos(j phi)) / 2 of it.
    const double phi = centre + 0.3 * M_PI / j;
    EXPECT_NEAR(lobeDiffusivity(s, phi), s.speeds[size_t(n)] * 0.5 * (1 + std::cos(j * phi)), 1e-13);
  }
  EXPECT_NEAR(meanLobeDiffusivity(s), quadratureMean(s), 1e-9);
  EXPECT_EQ(maxLobeDiffusivity(s), 3.0);
  EXPECT_THROW(validateCosineLobes(lobes({})), std::invalid_argument);
  EXPECT_THROW(validateCosineLobes(lobes({1.0, -0.1})), std::invalid_argument);
  EXPECT_NO_THROW(validateCosineLobes(lobes({1.0, 0.0})));
}

TEST(CosineLobes, Equation15WitkinKass) {
  const double a1 = 2.0, a2 = 0.5, alpha = (a1 + a2) / 4;
  const CosineLobeSpec s = lobes({a1, a2}, true);
  EXPECT_NEAR(lobeDiffusivity(s, 0.0), a1, 1e-14);
  EXPECT_NEAR(lobeDiffusivity(s, M_PI), a1, 1e-14);
  EXPECT_NEAR(lobeDiffusivity(s, M_PI / 2), a2, 1e-14);
  EXPECT_NEAR(lobeDiffusivity(s, -M_PI / 2), a2, 1e-14);
  for (double edge : {M_PI / 4, 3 * M_PI / 4, 5 * M_PI / 4, -M_PI / 4}) {
    EXPECT_NEAR(lobeDiffusivity(s, edge), alpha, 1e-12);
    EXPECT_NEAR(lobeDiffusivity(s, edge - 1e-7), alpha, 1e-9);
    EXPECT_NEAR(lobeDiffusivity(s, edge + 1e-7), alpha, 1e-9);
  }
  // The formula itself at an arbitrary angle of each branch.
  EXPECT_NEAR(lobeDiffusivity(s, 0.5), alpha + (a1 - alpha) / 2 * (1 + std::cos(2.0)), 1e-13);
  EXPECT_NEAR(lobeDiffusivity(s, 1.2), alpha + (a2 - alpha) / 2 * (1 + std::cos(4.8)), 1e-13);
  EXPECT_NEAR(meanLobeDiffusivity(s), quadratureMean(s), 1e-9);
  EXPECT_EQ(maxLobeDiffusivity(s), a1);
  // Not the four equal-width lobes of eq. 16 (the paper: "not a direct generalization").
  EXPECT_NEAR(lobeDiffusivity(lobes({a1, a2, a1, a2}), M_PI / 4), 0.0, 1e-14);
  EXPECT_THROW(validateCosineLobes(lobes({1.0}, true)), std::invalid_argument);
  EXPECT_THROW(validateCosineLobes(lobes({1.0, 0.0}, true)), std::invalid_argument);
}

namespace {

// Pure diffusion of u (Gray-Scott with F = k = 0 on v = 0).
template <int D>
RDSettings pureDiffusion(int n, RDBoundary boundary = RDBoundary::Periodic) {
  RDSettings s;
  s.model = "gray-scott";
  s.resolution.assign(D, n);
  s.size.assign(D, double(n));  // h = 1
  s.parameters = {0.0, 0.0};
  s.diffusion = {0.7, 0.0};
  s.boundary = boundary;
  s.tolerance = 1e-13;
  return s;
}

// One implicit step of u = 1 + cos(k x_axis) (periodic, h = 1) under the
// spec; returns the mode's amplitude after / before.
template <int D>
double modeFactor(const CosineLobeSpec& spec, int axis, double dt) {
  const int n = 16;
  RDSolver<D> rd(pureDiffusion<D>(n), *findModel("gray-scott"));
  const double k = kTwoPi * 2 / n;
  forEachCell<D>(rd.cells(), [&](const IVec<D>& c, size_t i) {
    rd.field(0)[i] = 1.0 + 0.5 * std::cos(k * (c[axis] + 0.5));
    rd.field(1)[i] = 0.0;
  });
  rd.setCosineLobes(spec);
  rd.step(dt);
  EXPECT_TRUE(rd.lastStats().diffusion.converged);
  double amp = 0, norm = 0;
  forEachCell<D>(rd.cells(), [&](const IVec<D>& c, size_t i) {
    const double m = std::cos(k * (c[axis] + 0.5));
    amp += (rd.field(0)[i] - 1.0) * m;
    norm += 0.5 * m * m;
  });
  return amp / norm;
}

// Backward Euler on a discrete Fourier mode: 1 / (1 + dt d a 4 sin^2(k/2)).
double implicitFactor(double a, double dt) {
  const double k = kTwoPi * 2 / 16;
  return 1.0 / (1.0 + dt * 0.7 * a * 4.0 * std::pow(std::sin(k / 2), 2));
}

}  // namespace

// u varying along x has theta = 0 or pi, along y theta = +-pi/2: four lobes
// (a1, a2, a1, a2) diffuse them at exactly a1 and a2; theta0 = pi/2 swaps them.
TEST(CosineLobes, TheGradientDirectionSelectsTheLobe) {
  const double a1 = 1.6, a2 = 0.3, dt = 3.0;
  const double tol = 1e-7;  // the system's face weights are single precision
  CosineLobeSpec s = lobes({a1, a2, a1, a2});
  EXPECT_NEAR(modeFactor<2>(s, 0, dt), implicitFactor(a1, dt), tol);
  EXPECT_NEAR(modeFactor<2>(s, 1, dt), implicitFactor(a2, dt), tol);
  s.theta0.assign(16 * 16, M_PI / 2);
  EXPECT_NEAR(modeFactor<2>(s, 0, dt), implicitFactor(a2, dt), tol);
  EXPECT_NEAR(modeFactor<2>(s, 1, dt), implicitFactor(a1, dt), tol);
  // Witkin-Kass: a1 along x, a2 along y.
  EXPECT_NEAR(modeFactor<2>(lobes({a1, a2}, true), 0, dt), implicitFactor(a1, dt), tol);
  EXPECT_NEAR(modeFactor<2>(lobes({a1, a2}, true), 1, dt), implicitFactor(a2, dt), tol);
  // 3D: x and y as in 2D; a gradient along z has no x-y angle and takes the mean.
  EXPECT_NEAR(modeFactor<3>(lobes({a1, a2, a1, a2}), 0, dt), implicitFactor(a1, dt), tol);
  EXPECT_NEAR(modeFactor<3>(lobes({a1, a2, a1, a2}), 1, dt), implicitFactor(a2, dt), tol);
  EXPECT_NEAR(modeFactor<3>(lobes({a1, a2, a1, a2}), 2, dt), implicitFactor((a1 + a2) / 4, dt), tol);
}

// Zero-flux walls, noise and a lobe operator that changes every step: mass is
// conserved and the L2 norm never grows, implicit and explicit (at 0.95 of
// the bound explicitDiffusionLimit reports); Dirichlet walls pull the state
// to their value.
TEST(CosineLobes, ConservesMassAndDecays) {
  for (RDIntegrator integ : {RDIntegrator::KimLin, RDIntegrator::ExplicitEuler, RDIntegrator::CrankNicolson}) {
    RDSettings s = pureDiffusion<2>(40, RDBoundary::Neumann);
    s.resolution = {40, 32};
    s.size = {40.0, 32.0};
    s.integrator = integ;
    RDSolver<2> rd(s, *findModel("gray-scott"));
    for (size_t i = 0; i < rd.field(0).size(); ++i) rd.field(0)[i] = uniform01(5, 0, i), rd.field(1)[i] = 0.0;
    CosineLobeSpec spec = lobes({2.0, 0.1, 1.0, 0.0, 0.6});
    spec.theta0.resize(rd.field(0).size());
    for (size_t i = 0; i < spec.theta0.size(); ++i) spec.theta0[i] = 0.01 * double(i);
    rd.setCosineLobes(spec);
    EXPECT_NEAR(rd.explicitDiffusionLimit(), 2.0 / (0.7 * 8.0 * 2.0), 1e-12);
    const double dt = integ == RDIntegrator::ExplicitEuler ? 0.95 * rd.explicitDiffusionLimit() : 4.0;
    const morphoflow::testing::MassAndNorm m = morphoflow::testing::stepExpectingDecay<2>(
        rd, dt, 30, "integrator " + std::to_string(int(integ)) + " ",
        [&] { ASSERT_TRUE(rd.lastStats().diffusion.converged); });
    if (HasFatalFailure()) return;
    EXPECT_NEAR(m.mass, m.mass0, 1e-10 * m.mass0) << "integrator " << int(integ);
    EXPECT_LT(m.norm, 0.9 * m.norm0) << "the noise must have diffused";
  }
  RDSettings s = pureDiffusion<2>(20, RDBoundary::Dirichlet);
  s.dirichletValues = {1.0, 0.0};
  RDSolver<2> rd(s, *findModel("gray-scott"));
  for (size_t i = 0; i < rd.field(0).size(); ++i) rd.field(0)[i] = 0.5 * uniform01(6, 0, i), rd.field(1)[i] = 0.0;
  rd.setCosineLobes(lobes({2.0, 0.5}, true));
  for (int i = 0; i < 60; ++i) rd.step(100.0);
  for (double v : rd.field(0).values()) EXPECT_NEAR(v, 1.0, 1e-6);
}

TEST(CosineLobes, RejectsBadSpecs) {
  RDSolver<2> rd(pureDiffusion<2>(8), *findModel("gray-scott"));
  CosineLobeSpec s = lobes({1.0, 2.0});
  s.theta0.assign(5, 0.0);
  EXPECT_THROW(rd.setCosineLobes(s), std::invalid_argument);
  s.theta0.clear();
  s.species = {2};
  EXPECT_THROW(rd.setCosineLobes(s), std::invalid_argument);
  s.species = {0};
  rd.setCosineLobes(s);
  EXPECT_TRUE(rd.lobed(0));
  EXPECT_FALSE(rd.lobed(1));
  DiffusionTensorSpec<2> t;
  EXPECT_THROW(rd.setDiffusionTensor(t), std::invalid_argument);
}

namespace {

// Pearson's Gray-Scott labyrinth (F = 0.04, k = 0.06) on a periodic 64^2 box
// from noise-perturbed patches (placed symmetrically in x and y); returns
// mean (dv/dx)^2 / mean (dv/dy)^2, and v's standard deviation in *spread.
double grayScottGradientRatio(const CosineLobeSpec* spec, int steps, double* spread) {
  RDSettings s;
  s.model = "gray-scott";
  s.resolution = {64, 64};
  s.size = {0.625, 0.625};
  s.diffusion = {2e-5, 1e-5};
  s.parameters = {0.04, 0.06};
  RDSolver<2> rd(s, *findModel("gray-scott"));
  forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
    const bool patch = (k[0] / 8 + k[1] / 8) % 3 == 0 && k[0] % 8 < 4 && k[1] % 8 < 4;
    rd.field(0)[i] = (patch ? 0.5 : 1.0) + 0.02 * (uniform01(9, 0, i) - 0.5);
    rd.field(1)[i] = (patch ? 0.25 : 0.0) + 0.02 * (uniform01(9, 1, i) - 0.5);
  });
  if (spec) rd.setCosineLobes(*spec);
  for (int i = 0; i < steps; ++i) rd.step(2.0);
  const Grid<double, 2>& v = rd.field(1);
  double gx = 0, gy = 0, sum = 0, sum2 = 0;
  forEachCell<2>(rd.cells(), [&](const IVec<2>& k, size_t i) {
    sum += v[i];
    sum2 += v[i] * v[i];
    const double dx = v[v.index({(k[0] + 1) % 64, k[1]})] - v[i], dy = v[v.index({k[0], (k[1] + 1) % 64})] - v[i];
    gx += dx * dx;
    gy += dy * dy;
  });
  const double n = double(v.size());
  *spread = std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
  return gx / gy;
}

}  // namespace

// Seed 001 fig. 4: a lobe that diffuses x-gradients faster smooths the
// pattern along x, so the stripes run along x; rotating the lobes by
// theta0 = pi/2 turns them. The isotropic run has no preferred axis.
TEST(CosineLobes, StretchGrayScottPatterns) {
  const int steps = 600;
  double spread[3];
  const double iso = grayScottGradientRatio(nullptr, steps, &spread[0]);
  CosineLobeSpec wk = lobes({2.0, 0.25}, true);
  const double along = grayScottGradientRatio(&wk, steps, &spread[1]);
  wk.theta0.assign(64 * 64, M_PI / 2);
  const double across = grayScottGradientRatio(&wk, steps, &spread[2]);
  for (double sd : spread) EXPECT_GT(sd, 0.05) << "a pattern must have grown";
  EXPECT_GT(iso, 0.85);
  EXPECT_LT(iso, 1.0 / 0.85);
  EXPECT_LT(along, 0.6) << "stripes along x: smooth in x";
  EXPECT_GT(across, 1.0 / 0.6) << "rotated by pi/2: stripes along y";
}
