// Smoke (fluid/smoke.h; Fedkiw, Stam & Jensen 2001): sources emit rate x
// time x volume, buoyancy starts a hot disc or ball moving as potential
// theory says a uniformly forced one must, decay is exact per step,
// confinement keeps a vortex's energy, and epsilon = 0 leaves the fluid as
// it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "core/error.h"
#include "core/simd_dispatch.h"
#include "fluid/fluid_solver.h"
#include "fluid/smoke.h"

using namespace morphoflow;

namespace {

FluidSettings closedBox(std::vector<int> res) {
  FluidSettings s;
  s.resolution = res;
  s.size.assign(res.size(), 1.0);
  s.viscosity = 0.0;
  s.smoke.enabled = true;
  return s;
}

template <int D>
double total(const Grid<float, D>& g, double h) {
  double sum = 0.0;
  for (float v : g.values()) sum += v;
  return sum * std::pow(h, D);
}

SmokeSource ball(int D, double r) {
  SmokeSource src;
  src.region.shape = D == 2 ? ObstacleShape::Circle : ObstacleShape::Sphere;
  src.region.center = {0.5, 0.5, 0.5};
  src.region.radius = r;
  return src;
}

// Whether cell k's centre lies within r of the domain's centre.
template <int D>
bool inside(const IVec<D>& k, double h, double r) {
  double d2 = 0.0;
  for (int a = 0; a < D; ++a) d2 += std::pow((k[a] + 0.5) * h - 0.5, 2);
  return d2 < r * r;
}

// Emission over a window that starts and ends inside steps, at rest.
template <int D>
void expectEmissionIsRateTimesTimeTimesVolume(std::vector<int> res, double r) {
  FluidSettings s = closedBox(res);
  SmokeSource src = ball(D, r);
  src.density = 3.0;
  src.temperature = 5.0;
  src.start = 0.013;
  src.end = 0.2;
  s.smoke.sources = {src};
  FluidSolver<D> f(s);
  for (int i = 0; i < 30; ++i) f.step(0.01);
  const double volume = D == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
  const double seconds = src.end - src.start;
  EXPECT_NEAR(total<D>(f.dye(), f.h()), 3.0 * seconds * volume, 0.02 * 3.0 * seconds * volume);
  EXPECT_NEAR(total<D>(f.temperature(), f.h()), 5.0 * seconds * volume, 0.02 * 5.0 * seconds * volume);
}

// A disc (ball) whose temperature is dT above ambient, in a box at rest:
// the forced field beta dT up inside it, projected, moves the inside
// uniformly at (1 - 1/D) of it (the Helmholtz projection of a uniform field
// restricted to a disc or ball; the added mass of a cylinder or sphere).
template <int D>
void expectAHotRegionStartsRisingAsTheFormulaSays(std::vector<int> res, double r) {
  FluidSettings s = closedBox(res);
  s.smoke.heat = 2.0;
  s.smoke.ambient = 0.3;
  s.advection = AdvectionScheme::SemiLagrangian;
  FluidSolver<D> f(s);
  const double dT = 1.5, dt = 1e-3;
  Grid<float, D>& T = f.temperature();
  for (size_t i = 0; i < T.size(); ++i) T[i] = float(s.smoke.ambient + (inside<D>(T.coord(i), f.h(), r) ? dT : 0.0));
  f.step(dt);
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < T.size(); ++i) {
    const IVec<D> k = T.coord(i);
    if (!inside<D>(k, f.h(), 0.8 * r)) continue;
    sum += f.velocity().atCell(k)[1];
    ++n;
  }
  const double expected = (1.0 - 1.0 / D) * dt * s.smoke.heat * dT;
  EXPECT_NEAR(sum / n, expected, 0.05 * expected);
}

double kineticEnergy(const FluidSolver<2>& f) {
  double e = 0.0;
  for (int a = 0; a < 2; ++a)
    for (float v : f.velocity()[a].values()) e += 0.5 * double(v) * v;
  return e * f.h() * f.h();
}

// A Gaussian vortex in a periodic box, to be carried by the dissipative
// semi-Lagrangian scheme; with [smoke] on or off.
std::unique_ptr<FluidSolver<2>> vortex(double epsilon, bool smoke = true) {
  FluidSettings s = closedBox({64, 64});
  for (auto& side : s.boundaries.sides) side.kind = BoundaryKind::Periodic;
  s.advection = AdvectionScheme::SemiLagrangian;
  s.smoke.enabled = smoke;
  s.smoke.vorticity = epsilon;
  auto f = std::make_unique<FluidSolver<2>>(s);
  for (int a = 0; a < 2; ++a) {
    Grid<float, 2>& g = f->velocity()[a];
    for (size_t i = 0; i < g.size(); ++i) {
      const IVec<2> k = g.coord(i);
      const double x = (k[0] + (a == 0 ? 0.0 : 0.5)) / 64 - 0.5, y = (k[1] + (a == 1 ? 0.0 : 0.5)) / 64 - 0.5;
      const double w = 4.0 * std::exp(-(x * x + y * y) / (2 * 0.08 * 0.08));
      g[i] = float(a == 0 ? -y * w : x * w);
    }
  }
  return f;
}

double energyAfter(FluidSolver<2>* f, int steps) {
  for (int i = 0; i < steps; ++i) f->step(0.01);
  return kineticEnergy(*f);
}

}  // namespace

TEST(Smoke, EmissionIsRateTimesTimeTimesVolumeIn2DAnd3D) {
  expectEmissionIsRateTimesTimeTimesVolume<2>({64, 64}, 0.1);
  expectEmissionIsRateTimesTimeTimesVolume<3>({24, 24, 24}, 0.2);
}

TEST(Smoke, AHotRegionStartsRisingAtTheBuoyancyTheFormulaGives) {
  expectAHotRegionStartsRisingAsTheFormulaSays<2>({128, 128}, 0.1);
  expectAHotRegionStartsRisingAsTheFormulaSays<3>({48, 48, 48}, 0.15);
}

TEST(Smoke, DissipationAndCoolingAreExactPerStep) {
  FluidSettings s = closedBox({16, 16});
  s.smoke.dissipation = 0.7;
  s.smoke.cooling = 1.9;
  s.smoke.ambient = 0.25;
  FluidSolver<2> f(s);
  f.dye().fill(2.0f);
  f.temperature().fill(1.25f);
  const double dt = 0.05;
  for (int i = 0; i < 20; ++i) f.step(dt);
  const double t = 20 * dt;
  for (float v : f.dye().values()) EXPECT_NEAR(v, 2.0 * std::exp(-0.7 * t), 2e-6);
  for (float v : f.temperature().values()) EXPECT_NEAR(v, 0.25 + 1.0 * std::exp(-1.9 * t), 2e-6);
}

TEST(Smoke, ConfinementKeepsMoreOfAVortexsEnergyAndZeroIsTodaysFluid) {
  const double start = energyAfter(vortex(0.0).get(), 0);
  const double without = energyAfter(vortex(0.0).get(), 100);
  const double with = energyAfter(vortex(0.5).get(), 100);
  EXPECT_LT(without, 0.97 * start) << "the semi-Lagrangian scheme loses energy";
  // Measured at 64^2 over 100 steps: 34% of the energy lost without, 19% of
  // that put back with epsilon = 0.5, and more with a larger epsilon.
  EXPECT_GT(with, without + 0.15 * (start - without)) << "confinement puts back part of what the scheme lost";
  EXPECT_GT(with, energyAfter(vortex(0.2).get(), 100));
  EXPECT_LT(with, start) << "and adds no energy of its own";
  // epsilon = 0 with [smoke] on (no sources, no buoyancy): bitwise the fluid without smoke.
  auto smoky = vortex(0.0, true), plain = vortex(0.0, false);
  energyAfter(smoky.get(), 10);
  energyAfter(plain.get(), 10);
  for (int a = 0; a < 2; ++a) EXPECT_EQ(smoky->velocity()[a].values(), plain->velocity()[a].values());
}

// A closed box without dissipation: smoke stirred by a vortex keeps its
// total within the advection's known change. Neither semi-Lagrangian nor
// MacCormack advection conserves mass; measured at 64^2 over 200 steps (two
// turns of a Gaussian vortex carrying an off-centre blob): +3.6% with
// MacCormack (the default; allowed 5%), -8.6% with semi-Lagrangian
// (allowed 10%).
TEST(Smoke, AClosedBoxKeepsItsSmokeWithinTheAdvectionsLoss) {
  for (AdvectionScheme scheme : {AdvectionScheme::MacCormack, AdvectionScheme::SemiLagrangian}) {
    auto f = vortex(0.0);
    FluidSettings s = f->settings();
    s.advection = scheme;
    for (auto& side : s.boundaries.sides) side.kind = BoundaryKind::Wall;
    FluidSolver<2> g(s);
    for (int a = 0; a < 2; ++a) g.velocity()[a] = f->velocity()[a];
    Grid<float, 2>& smoke = g.dye();
    for (size_t i = 0; i < smoke.size(); ++i) {
      const IVec<2> k = smoke.coord(i);
      const double x = (k[0] + 0.5) / 64 - 0.62, y = (k[1] + 0.5) / 64 - 0.5;
      smoke[i] = float(std::exp(-(x * x + y * y) / (2 * 0.05 * 0.05)));
    }
    const double before = total<2>(smoke, g.h());
    for (int i = 0; i < 200; ++i) g.step(0.01);
    const double after = total<2>(g.dye(), g.h());
    const bool mac = scheme == AdvectionScheme::MacCormack;
    EXPECT_NEAR(after, before, (mac ? 0.05 : 0.10) * before) << (mac ? "maccormack" : "semi-lagrangian");
  }
}

// A source moving along x (motion = centre as expressions in t), fluid at
// rest: it emits rate x time x area in all, laid along its path, so the
// smoke's centroid is the path's mean position.
TEST(Smoke, AMovingSourceLaysItsSmokeAlongItsPath) {
  FluidSettings s = closedBox({64, 64});
  SmokeSource src = ball(2, 0.08);
  src.density = 2.0;
  src.motion = {"0.3 + 0.4 * t", "0.5"};
  src.end = 1.0;
  s.smoke.sources = {src};
  FluidSolver<2> f(s);
  for (int i = 0; i < 50; ++i) f.step(0.02);
  const double area = M_PI * 0.08 * 0.08;
  EXPECT_NEAR(total<2>(f.dye(), f.h()), 2.0 * 1.0 * area, 0.02 * 2.0 * area);
  double mx = 0, m = 0;
  for (size_t i = 0; i < f.dye().size(); ++i) {
    mx += f.dye()[i] * (f.dye().coord(i)[0] + 0.5) * f.h();
    m += f.dye()[i];
  }
  EXPECT_NEAR(mx / m, 0.3 + 0.4 * 0.5, 0.005);
}

// A motion that takes the source far away lays nothing and stays defined;
// one that is not finite while the source emits stops the run, naming it.
TEST(Smoke, AMotionFarAwayEmitsNothingAndANonFiniteOneStopsTheRun) {
  FluidSettings s = closedBox({32, 32});
  SmokeSource src = ball(2, 0.08);
  src.density = 2.0;
  src.motion = {"0.5", "0.5 + 1e30 * (t - 0.01)"};  // out of the box (and past any int) after the first step
  s.smoke.sources = {src};
  FluidSolver<2> away(s);
  away.step(0.02);
  const double once = total<2>(away.dye(), away.h());
  EXPECT_NEAR(once, 2.0 * 0.02 * M_PI * 0.08 * 0.08, 0.02 * once) << "the first step's mid-point is inside";
  for (int i = 0; i < 5; ++i) away.step(0.02);
  EXPECT_EQ(total<2>(away.dye(), away.h()), once);
  for (const char* bad : {"1 / (t - 0.05)", "sqrt(t - 0.1)"}) {  // inf at t = 0.05 (mid-step), NaN before t = 0.1
    src.motion = {"0.5", bad};
    s.smoke.sources = {src};
    FluidSolver<2> f(s);
    try {
      for (int i = 0; i < 3; ++i) f.step(0.1);
      ADD_FAILURE() << bad << ": no error";
    } catch (const NonFiniteError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("t = 0.05"), std::string::npos) << e.what();
    }
  }
}

namespace {

// Eq. 11 in double at an interior cell: omega by central differences of the
// centre velocities, N = grad|omega| / |grad|omega||, f = epsilon h N x omega.
template <int D>
std::array<double, 3> confinementAt(const MacVelocity<D>& u, const IVec<D>& k, double epsilon) {
  const double h = u.h();
  auto uc = [&](int c, IVec<D> q) { return 0.5 * (double(u[c](q)) + double(u[c](q + unitVector<D>(c)))); };
  auto omega = [&](const IVec<D>& q) {
    auto d = [&](int c, int b) { return (uc(c, q + unitVector<D>(b)) - uc(c, q - unitVector<D>(b))) / (2 * h); };
    if constexpr (D == 2) return std::array<double, 3>{0, 0, d(1, 0) - d(0, 1)};
    else return std::array<double, 3>{d(2, 1) - d(1, 2), d(0, 2) - d(2, 0), d(1, 0) - d(0, 1)};
  };
  auto mag = [&](const IVec<D>& q) {
    const auto w = omega(q);
    return std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  };
  std::array<double, 3> eta{0, 0, 0};
  double len = 0;
  for (int b = 0; b < D; ++b) {
    eta[size_t(b)] = (mag(k + unitVector<D>(b)) - mag(k - unitVector<D>(b))) / (2 * h);
    len += eta[size_t(b)] * eta[size_t(b)];
  }
  len = std::sqrt(len);
  const auto w = omega(k);
  const double N[3] = {eta[0] / len, eta[1] / len, eta[2] / len}, s = epsilon * h;
  return {s * (N[1] * w[2] - N[2] * w[1]), s * (N[2] * w[0] - N[0] * w[2]), s * (N[0] * w[1] - N[1] * w[0])};
}

// The forces' passes on a swirl with walls or periodic sides: interior
// faces gain dt times the mean of eq. 11 at their two cells (within float
// rounding), and the AVX2 and four-lane loops give bitwise the same velocity.
template <int D>
void expectConfinementIsEq11(const std::array<bool, D>& periodic) {
  const int n = D == 2 ? 40 : 20;
  MacVelocity<D> u(IVec<D>(n), 1.0 / n, periodic);
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      const Vec<D> x = u.layout(a).toWorld(u[a].coord(i));
      const double z = D == 3 ? x[D - 1] : 0.0, p = 2 * 3.14159265358979 * (x[0] + 0.3 * x[1] + 0.6 * z);
      u[a][i] = float(a == 0   ? std::sin(p) * std::cos(7.0 * x[1])
                      : a == 1 ? std::cos(3.0 * p) * (1 + z)
                               : 0.5 * std::sin(p + x[1]));
    }
  SmokeSettings s;
  s.enabled = true;
  s.vorticity = 1.5;
  Grid<float, D> rho(u.cells(), 0.0f), t(u.cells(), 0.0f);
  const double dt = 0.1;
  WorkPool pool;
  MacVelocity<D> wide = u, narrow = u;
  const bool was = useAvx2();
  applySmokeForces<D>(s, {0, 1, 0}, rho, t, dt, &wide, &pool);
  setUseAvx2(false);
  applySmokeForces<D>(s, {0, 1, 0}, rho, t, dt, &narrow, &pool);
  setUseAvx2(was);
  double worst = 0, largest = 0;
  for (int a = 0; a < D; ++a) {
    EXPECT_EQ(0, std::memcmp(wide[a].data(), narrow[a].data(), wide[a].size() * sizeof(float))) << "component " << a;
    for (size_t i = 0; i < u[a].size(); ++i) {
      const IVec<D> k = u[a].coord(i);
      bool interior = true;  // both cells and their curls' stencils inside
      for (int b = 0; b < D; ++b) interior &= k[b] >= 3 && k[b] <= n - 4;
      if (!interior) continue;
      const double f = 0.5 * (confinementAt<D>(u, k - unitVector<D>(a), 1.5)[size_t(a)] +
                              confinementAt<D>(u, k, 1.5)[size_t(a)]);
      worst = std::max(worst, std::abs(double(wide[a][i]) - u[a][i] - dt * f));
      largest = std::max(largest, std::abs(dt * f));
    }
  }
  EXPECT_GT(largest, 1e-3) << "the swirl is confined";
  EXPECT_LT(worst, 1e-6) << "eq. 11";
}

}  // namespace

TEST(Smoke, ConfinementIsEq11AtEveryVectorWidth) {
  expectConfinementIsEq11<2>({false, false});
  expectConfinementIsEq11<2>({true, false});
  expectConfinementIsEq11<3>({false, false, false});
  expectConfinementIsEq11<3>({true, false, true});
}
