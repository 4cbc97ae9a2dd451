// Advection: a smooth blob carried once around a solid-body rotation comes
// back close to where it started, MacCormack measurably closer than
// first-order semi-Lagrangian; any CFL stays bounded.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/simd_dispatch.h"
#include "fluid/advection.h"
#include "fluid/fluid_solver.h"

using namespace morphoflow;

namespace {
const double kPi = 3.14159265358979323846;

// Relative L2 error of a blob after one revolution at CFL ~ 4.
double revolutionError(AdvectionScheme scheme, double* maxValue) {
  const int n = 128;
  const double h = 1.0 / n;
  IVec<2> cells(n, n);
  MacVelocity<2> u(cells, h, {false, false});
  for (int a = 0; a < 2; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      Vec<2> x = u.layout(a).toWorld(u[a].coord(i));
      // u = omega x (x - c), omega = 2 pi: one revolution per unit time.
      u[a][i] = float(a == 0 ? -2 * kPi * (x[1] - 0.5) : 2 * kPi * (x[0] - 0.5));
    }
  auto layout = Layout<2>::cellCentred(h, cells, {false, false});
  Grid<float, 2> q(cells), next(cells), start(cells);
  for (size_t i = 0; i < q.size(); ++i) {
    Vec<2> x = layout.toWorld(q.coord(i));
    double r2 = (x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.75) * (x[1] - 0.75);
    q[i] = float(std::exp(-r2 / (2 * 0.06 * 0.06)));
  }
  start = q;
  const int steps = 100;
  for (int s = 0; s < steps; ++s) {
    advectField<2>(q, layout, u, 1.0 / steps, scheme, &next);
    std::swap(q, next);
  }
  double e2 = 0, n2 = 0, mx = 0;
  for (size_t i = 0; i < q.size(); ++i) {
    e2 += double(q[i] - start[i]) * double(q[i] - start[i]);
    n2 += double(start[i]) * double(start[i]);
    mx = std::max(mx, double(q[i]));
  }
  *maxValue = mx;
  return std::sqrt(e2 / n2);
}
}  // namespace

TEST(Advection, BlobReturnsAfterOneRevolution) {
  double mxSL, mxMC, mxBF;
  double sl = revolutionError(AdvectionScheme::SemiLagrangian, &mxSL);
  double mc = revolutionError(AdvectionScheme::MacCormack, &mxMC);
  double bf = revolutionError(AdvectionScheme::Bfecc, &mxBF);
  EXPECT_LT(sl, 0.6) << "semi-Lagrangian error";
  EXPECT_LT(mc, 0.2) << "MacCormack error";
  EXPECT_LT(bf, 0.2) << "BFECC error";
  // Second-order schemes are measurably better than first order.
  EXPECT_LT(mc, 0.5 * sl) << "MacCormack " << mc << " vs semi-Lagrangian " << sl;
  EXPECT_LT(bf, 0.5 * sl) << "BFECC " << bf << " vs semi-Lagrangian " << sl;
  // Limited schemes create no new maxima.
  EXPECT_LE(mxMC, 1.0 + 1e-6);
  EXPECT_LE(mxBF, 1.0 + 1e-6);
  EXPECT_LE(mxSL, 1.0 + 1e-6);
}

TEST(Advection, CavityAtCfl5StaysBounded) {
  FluidSettings s;
  s.resolution = {64, 64};
  s.size = {1.0, 1.0};
  s.viscosity = 1e-3;
  s.boundaries.sides[3].wallVelocity = {1.0, 0.0, 0.0};  // lid on the top (y high)
  for (AdvectionScheme scheme : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack}) {
    s.advection = scheme;
    FluidSolver<2> f(s);
    const double dt = 5.0 * f.h() / 1.0;  // CFL 5 based on the lid speed
    for (int i = 0; i < 200; ++i) {
      f.step(dt);
      ASSERT_TRUE(std::isfinite(f.maxSpeed()));
    }
    // Semi-Lagrangian values are interpolants of earlier ones: bounded by the lid.
    EXPECT_LT(f.maxSpeed(), 1.5 * std::sqrt(2.0));
    EXPECT_GT(f.maxSpeed(), 0.1);  // the lid drives a flow
  }
}

// The fast semi-Lagrangian pass (four, eight or sixteen samples at a time on walled domains,
// the start velocity from contiguous loads inside each row, scalar on
// periodic ones and at row ends) against the plain definition:
// foot = x - dt u(x - dt/2 u(x)) traced in double with sampleLinear, then
// the field sampled there. Odd sizes put cells in every code path.
template <int D>
void expectMatchesReferenceTrace(const std::array<bool, D>& periodic, double amplitude) {
  IVec<D> cells(13);
  cells[0] = 37;  // two groups of sixteen lanes, one of eight and the scalar end
  cells[1] = D == 2 ? 29 : 11;
  const double h = 1.0 / cells[0], dt = 2.5 * h;  // CFL ~ 2.5 amplitude: feet leave the domain
  MacVelocity<D> u(cells, h, periodic);
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      Vec<D> x = u.layout(a).toWorld(u[a].coord(i));
      u[a][i] = float(amplitude * (std::sin(3.0 * x[(a + 1) % D] + a) + 0.4 * std::cos(5.0 * x[a])));
    }
  for (int a = 0; a < D; ++a)  // the duplicate face of a periodic axis equals face 0
    if (periodic[size_t(a)])
      for (size_t i = 0; i < u[a].size(); ++i) {
        IVec<D> k = u[a].coord(i);
        if (k[a] == cells[a]) u[a][i] = u[a](k - cells[a] * unitVector<D>(a));
      }
  // Cell centres, and each face grid (whose samples sit half a cell away from
  // the other components' samples along x: the row-velocity taps shift).
  for (int layoutAxis = -1; layoutAxis < D; ++layoutAxis) {
    const Layout<D> layout = layoutAxis < 0 ? Layout<D>::cellCentred(h, cells, periodic)
                                            : u.layout(layoutAxis);
    const IVec<D> dims = layoutAxis < 0 ? cells : u[layoutAxis].dims();
    Grid<float, D> q(dims), out(dims);
    for (size_t i = 0; i < q.size(); ++i) {
      Vec<D> x = layout.toWorld(q.coord(i));
      q[i] = float(std::cos(4.0 * x[0]) * std::sin(3.0 * x[1] + 0.5));
    }
    advectField<D>(q, layout, u, dt, AdvectionScheme::SemiLagrangian, &out);
    double worst = 0;
    for (size_t i = 0; i < q.size(); ++i) {
      Vec<D> foot = traceBack<D>(u, layout.toWorld(q.coord(i)), dt);
      worst = std::max(worst, std::abs(double(out[i]) - double(sampleLinear(q, layout, foot))));
    }
    EXPECT_LT(worst, 2e-5) << "layout axis " << layoutAxis;  // single against double precision
    // Sixteen lanes at a time (where the CPU has AVX-512), eight (AVX2)
    // and four give bitwise the same fields, the MacCormack pass's stencil
    // bounds included.
    for (AdvectionScheme scheme : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack}) {
      Grid<float, D> widest(dims), wide(dims), narrow(dims);
      const bool was = useAvx2(), was512 = useAvx512();
      advectField<D>(q, layout, u, dt, scheme, &widest);
      setUseAvx512(false);
      advectField<D>(q, layout, u, dt, scheme, &wide);
      setUseAvx2(false);
      advectField<D>(q, layout, u, dt, scheme, &narrow);
      setUseAvx2(was);
      setUseAvx512(was512);
      EXPECT_EQ(0, std::memcmp(widest.data(), narrow.data(), wide.size() * sizeof(float)))
          << "layout axis " << layoutAxis;
      EXPECT_EQ(0, std::memcmp(wide.data(), narrow.data(), wide.size() * sizeof(float)))
          << "layout axis " << layoutAxis;
    }
  }
}

TEST(Advection, FastPassMatchesTheReferenceTrace) {
  // CFL ~ 2.5, and a gentle flow (CFL ~ 0.1) whose neighbouring samples
  // mostly trace back into neighbouring cells (the contiguous-load path).
  for (double amplitude : {1.0, 0.05}) {
    expectMatchesReferenceTrace<2>({false, false}, amplitude);
    expectMatchesReferenceTrace<2>({true, false}, amplitude);
    expectMatchesReferenceTrace<3>({false, false, false}, amplitude);
    expectMatchesReferenceTrace<3>({false, true, true}, amplitude);
  }
}

namespace {

// The vector kernels' feet (traceCellFeet, single precision) against the
// double-precision traceBack, from the cell centres of the velocity's own
// grid and of a finer and a coarser one, in a swirling flow that carries
// feet out of the domain (clamped) at CFL ~ 3; every vector width.
template <int D>
void checkCellFeet(int n, int gridCells) {
  const double h = 1.0 / n;
  MacVelocity<D> u(IVec<D>(n), h, std::array<bool, D>{});
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      const Vec<D> x = u.layout(a).toWorld(u[a].coord(i));
      const double s = std::sin(kPi * x[0]) * std::sin(kPi * x[1]);
      u[a][i] = float(a == 0 ? 3.0 * s + 0.5 * x[1] : a == 1 ? -2.0 * s * std::cos(3.0 * x[0]) : 0.7 * x[0]);
    }
  const double dt = 1.0 * h, gh = 1.0 / gridCells;
  const IVec<D> cells(gridCells);
  const bool wide = useAvx2(), widest = useAvx512();
  for (int lanes : {16, 8, 4}) {
    setUseAvx512(widest && lanes == 16);
    setUseAvx2(wide && lanes >= 8);
    std::array<std::vector<float>, D> feet;
    std::array<float*, D> out;
    for (int a = 0; a < D; ++a) {
      feet[size_t(a)].resize(size_t(std::pow(gridCells, D)));
      out[size_t(a)] = feet[size_t(a)].data();
    }
    const bool done = traceCellFeet<D>(u, dt, cells, gh, out);
    setUseAvx2(wide);
    setUseAvx512(widest);
    ASSERT_TRUE(done);
    double worst = 0.0, moved = 0.0;
    for (size_t k = 0; k < feet[0].size(); ++k) {  // cells in row order
      IVec<D> c = IVec<D>(0);
      size_t rest = k;
      for (int a = 0; a < D; ++a) {
        c[a] = int(rest % size_t(gridCells));
        rest /= size_t(gridCells);
      }
      const Vec<D> x = (Vec<D>(c) + 0.5) * gh;
      const Vec<D> ref = traceBack<D>(u, x, dt) / gh - Vec<D>(0.5);
      for (int a = 0; a < D; ++a) {
        worst = std::max(worst, std::abs(double(feet[size_t(a)][k]) - ref[a]));
        moved = std::max(moved, std::abs(ref[a] - c[a]));
      }
    }
    EXPECT_GT(moved, 1.0) << "the flow moves feet by cells";
    EXPECT_LT(worst, 1e-4) << D << "D, " << n << " fluid cells, " << gridCells << " grid cells, " << lanes << " lanes";
  }
}

}  // namespace

TEST(Advection, CellFeetMatchTheDoubleTrace) {
  checkCellFeet<2>(48, 48);
  checkCellFeet<2>(48, 96);
  checkCellFeet<2>(48, 30);
  checkCellFeet<3>(20, 20);
  checkCellFeet<3>(20, 33);
}

// A periodic axis is left to the caller's own trace.
TEST(Advection, CellFeetDeclinePeriodicAxes) {
  MacVelocity<2> u(IVec<2>(16), 1.0 / 16, {true, false});
  std::vector<float> x(256), y(256);
  EXPECT_FALSE(traceCellFeet<2>(u, 0.01, IVec<2>(16), 1.0 / 16, {x.data(), y.data()}));
}

namespace {

// Rows of empty space (one value, bitwise, in every sample a trace can
// reach) are written without tracing, and the field is bitwise what the
// full passes give: a compact blob (exact zeros around it), an ambient
// value with a hot spot, and a region of -0 (which interpolates to +0), in
// a swirl that moves samples by up to ~2 cells, for every scheme.
template <int D>
void expectEmptyRowsSkippedChangeNothing() {
  const int n = D == 2 ? 64 : 40;
  const double h = 1.0 / n, dt = 1.6 * h;
  MacVelocity<D> u(IVec<D>(n), h, std::array<bool, D>{});
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < u[a].size(); ++i) {
      const Vec<D> x = u.layout(a).toWorld(u[a].coord(i));
      const double s = std::sin(kPi * x[0]) * std::sin(kPi * x[1]);
      u[a][i] = float(a == 0 ? s : a == 1 ? -s * std::cos(3.0 * x[0]) : 0.3 * s);
    }
  const std::optional<std::array<int, D>> reach = traceReach<D>(u, dt);
  ASSERT_TRUE(reach);
  const Layout<D> layout = Layout<D>::cellCentred(h, IVec<D>(n), std::array<bool, D>{});
  auto blob = [&](const Vec<D>& x, double cy) {
    double r2 = (x[0] - 0.4) * (x[0] - 0.4) + (x[1] - cy) * (x[1] - cy);
    if (D == 3) r2 += (x[D - 1] - 0.5) * (x[D - 1] - 0.5);
    const double v = std::exp(-r2 / (2 * 0.03 * 0.03));
    return v < 1e-3 ? 0.0 : v;
  };
  const IVec<D> cells(n);
  Grid<float, D> smoke(cells), ambient(cells), negativeZero(cells);
  for (size_t i = 0; i < smoke.size(); ++i) {
    const Vec<D> x = layout.toWorld(smoke.coord(i));
    smoke[i] = float(blob(x, 0.6));
    ambient[i] = float(0.25 + blob(x, 0.4));
    negativeZero[i] = x[1] < 0.5 ? -0.0f : float(blob(x, 0.75));
  }
  for (AdvectionScheme scheme : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::Bfecc})
    for (const Grid<float, D>* q : {&smoke, &ambient, &negativeZero}) {
      Grid<float, D> full(cells), skipped(cells);
      const size_t all = advectField<D>(*q, layout, u, dt, scheme, &full);
      const size_t some = advectField<D>(*q, layout, u, dt, scheme, &skipped, nullptr, &*reach);
      EXPECT_EQ(0, std::memcmp(full.data(), skipped.data(), full.size() * sizeof(float)))
          << D << "D, scheme " << int(scheme);
      EXPECT_LT(some, all / 2) << "most rows are empty space";
    }
}

}  // namespace

TEST(Advection, RowsOfEmptySpaceAreSkippedBitwiseExactly) {
  expectEmptyRowsSkippedChangeNothing<2>();
  expectEmptyRowsSkippedChangeNothing<3>();
  // A periodic axis or a non-finite velocity traces everything.
  MacVelocity<2> periodic(IVec<2>(8), 0.125, {true, false});
  EXPECT_FALSE(traceReach<2>(periodic, 0.1));
  MacVelocity<2> broken(IVec<2>(8), 0.125, {false, false});
  broken[1][5] = std::nanf("");
  EXPECT_FALSE(traceReach<2>(broken, 0.1));
}
