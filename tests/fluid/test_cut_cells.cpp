// Cut-cell obstacles (fluid/cut_cells.h, fluid/surface_forces.h): the open
// fractions measure the fluid part of the faces, the no-slip wall sits at
// the obstacle's surface (second order, where the staircase is first), a
// solid on the cell faces projects as the staircase does, and the surface
// integral of the pressure gives Archimedes' force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/random.h"
#include "fluid/fluid_solver.h"
#include "fluid/surface_forces.h"

using namespace morphoflow;

namespace {

const double kPi = 3.14159265358979323846;

ObstacleSpec box(std::array<double, 3> centre, std::array<double, 3> half, ObstacleBoundary b) {
  ObstacleSpec o;
  o.shape = ObstacleShape::Box;
  o.center = centre;
  o.halfSize = half;
  o.boundary = b;
  return o;
}

// The surface's area: the sum of the elements' area vectors' lengths.
template <int D>
double surfaceArea(const FluidSolver<D>& f) {
  double area = 0;
  for (const SurfaceElement& e : f.cutSurface()) area += std::hypot(e.area[0], e.area[1], e.area[2]);
  return area;
}

}  // namespace

// A box edge at a fraction of a cell opens the faces it crosses by that
// fraction; a circle's and a sphere's surface elements add up to their area.
TEST(CutCells, OpenFractionsMeasureTheFluidPartOfTheFaces) {
  FluidSettings s;
  s.resolution = {32, 32};
  s.size = {1.0, 1.0};
  s.obstacles = {box({0.5, 0.0, 0}, {1.0, 3.3 / 32, 0}, ObstacleBoundary::Cut)};  // top at y = 3.3 cells
  FluidSolver<2> flat(s);
  // The x faces of row 3 (y in [3h, 4h]) are 0.7 open, row 2 closed, row 4 open.
  EXPECT_NEAR(flat.constraints().open[0](IVec<2>(10, 3)), 0.7, 1e-5);
  EXPECT_EQ(flat.constraints().open[0](IVec<2>(10, 2)), 0.0f);
  EXPECT_EQ(flat.constraints().open[0](IVec<2>(10, 4)), 1.0f);
  EXPECT_EQ(flat.constraints().open[1](IVec<2>(10, 3)), 0.0f);  // y = 3h, inside
  EXPECT_EQ(flat.constraints().open[1](IVec<2>(10, 4)), 1.0f);

  ObstacleSpec c;
  c.center = {0.5, 0.5, 0.5};
  c.radius = 0.23;
  s.obstacles = {c};
  s.resolution = {64, 64};
  EXPECT_NEAR(surfaceArea(FluidSolver<2>(s)) / (2 * kPi * c.radius), 1.0, 5e-3);
  c.shape = ObstacleShape::Sphere;
  s.obstacles = {c};
  s.resolution = {48, 48, 48};
  s.size = {1.0, 1.0, 1.0};
  EXPECT_NEAR(surfaceArea(FluidSolver<3>(s)) / (4 * kPi * c.radius * c.radius), 1.0, 2e-2);
}

namespace {

// Steady plane Poiseuille flow between two walls that are box obstacles
// (y < a and y > b, neither on a cell face), driven by a body force along
// the periodic x: u = F / (2 nu) (y - a) (b - y). Returns the largest error
// of u over the faces in the channel, relative to its peak.
double poiseuilleError(int n, ObstacleBoundary boundary) {
  const double a = 0.1234, b = 0.8765, F = 1.0, nu = 1.0;
  FluidSettings s;
  s.resolution = {4, n};
  s.size = {4.0 / n, 1.0};
  s.boundaries.sides[0].kind = s.boundaries.sides[1].kind = BoundaryKind::Periodic;
  s.obstacles = {box({0.5 * s.size[0], 0.0, 0}, {s.size[0], a, 0}, boundary),
                 box({0.5 * s.size[0], 1.0, 0}, {s.size[0], 1.0 - b, 0}, boundary)};
  s.viscosity = nu;
  s.force = {F, 0, 0};
  s.viscosityTolerance = 1e-13;
  s.pressureTolerance = 1e-13;
  FluidSolver<2> f(s);
  for (int i = 0; i < 12; ++i) f.step(10.0);  // implicit viscosity: each step cuts the transient by ~1/170
  const double peak = F / (8 * nu) * (b - a) * (b - a);
  double worst = 0;
  for (int j = 0; j < n; ++j) {
    const double y = (j + 0.5) / n;
    if (y <= a || y >= b) continue;
    const double exact = F / (2 * nu) * (y - a) * (b - y);
    worst = std::max(worst, std::abs(f.velocity()[0](IVec<2>(1, j)) - exact) / peak);
  }
  return worst;
}

}  // namespace

// The no-slip condition at the cut surface (Gibou et al. 2002) converges at
// second order; the staircase, whose walls sit at the cell faces, at first.
TEST(CutCells, NoSlipAtTheSurfaceConvergesAtSecondOrder) {
  double cut[3], voxel[3];
  for (int r = 0; r < 3; ++r) {
    cut[r] = poiseuilleError(16 << r, ObstacleBoundary::Cut);
    voxel[r] = poiseuilleError(16 << r, ObstacleBoundary::Voxel);
  }
  const double cutOrder = std::log2(cut[1] / cut[2]), voxelOrder = std::log2(voxel[1] / voxel[2]);
  std::cout << "cut: errors " << cut[0] << " " << cut[1] << " " << cut[2] << " (order " << cutOrder << "); voxel: "
            << voxel[0] << " " << voxel[1] << " " << voxel[2] << " (order " << voxelOrder << ")\n";
  EXPECT_GT(cutOrder, 1.7);
  EXPECT_LT(voxelOrder, 1.5);
  EXPECT_LT(cut[2], 0.2 * voxel[2]);
}

// A box whose sides lie on cell faces: the cut faces are open or closed
// whole, so the pressure system and the projection are the staircase's, bit
// for bit.
TEST(CutCells, ASolidOnTheCellFacesProjectsAsTheStaircase) {
  for (int d : {2, 3}) {
    auto run = [&](auto dim, ObstacleBoundary boundary) {
      constexpr int D = decltype(dim)::value;
      FluidSettings s;
      s.resolution.assign(D, 32);
      s.size.assign(D, 1.0);
      s.obstacles = {box({0.5, 0.5, 0.5}, {0.125, 0.25, 0.125}, boundary)};  // sides at 12, 8, 20 and 24 cells
      FluidSolver<D> f(s);
      MacVelocity<D> u = f.velocity();
      for (int a = 0; a < D; ++a)
        for (size_t i = 0; i < u[a].size(); ++i) u[a][i] = float(uniform01(3, uint64_t(a), i) - 0.5);
      f.constraints().apply(&u);
      f.projection().project(&u, 0.1, 1.0);
      std::vector<float> out;
      for (int a = 0; a < D; ++a) out.insert(out.end(), u[a].values().begin(), u[a].values().end());
      return out;
    };
    const auto cut = d == 2 ? run(std::integral_constant<int, 2>{}, ObstacleBoundary::Cut)
                            : run(std::integral_constant<int, 3>{}, ObstacleBoundary::Cut);
    const auto voxel = d == 2 ? run(std::integral_constant<int, 2>{}, ObstacleBoundary::Voxel)
                              : run(std::integral_constant<int, 3>{}, ObstacleBoundary::Voxel);
    ASSERT_EQ(cut.size(), voxel.size());
    EXPECT_EQ(std::memcmp(cut.data(), voxel.data(), cut.size() * sizeof(float)), 0) << d << "D";
  }
}

// Fluid at rest under gravity g in a closed box: the projection gives the
// hydrostatic pressure, and its integral over a submerged cut circle is
// Archimedes' force rho g V, upwards.
TEST(CutCells, TheSurfacePressureGivesArchimedesForce) {
  FluidSettings s;
  s.resolution = {96, 96};
  s.size = {1.0, 1.0};
  ObstacleSpec c;
  c.center = {0.47, 0.53, 0};
  c.radius = 0.17;
  s.obstacles = {c};
  s.force = {0, -9.81, 0};
  s.viscosity = 0.0;
  s.pressureTolerance = 1e-12;
  FluidSolver<2> f(s);
  f.step(0.01);
  const std::array<double, 3> F = surfaceForce<2>(f.cutSurface(), f.velocity(), f.pressure(), 0.0);
  const double archimedes = 9.81 * kPi * c.radius * c.radius;
  std::cout << "force / (rho g V): " << F[1] / archimedes << ", sideways " << F[0] / archimedes << "\n";
  EXPECT_NEAR(F[1] / archimedes, 1.0, 5e-3);
  EXPECT_NEAR(F[0] / archimedes, 0.0, 5e-3);
}

// Every shape has a cut surface: a signed-distance picture of a circle
// (64 x 64 samples over the domain) and a grey, antialiased picture of a
// disc (only an inside and an outside, found by bisection) give the
// circle's perimeter.
TEST(CutCells, ImageAndSdfShapesHaveTheirSurface) {
  const double r = 0.27, cx = 0.5, cy = 0.48;
  ObstacleSpec sdf, image;
  sdf.shape = ObstacleShape::Sdf;
  image.shape = ObstacleShape::Image;
  for (ObstacleSpec* o : {&sdf, &image}) o->fieldWidth = o->fieldHeight = 64;
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      const double x = (i + 0.5) / 64, y = 1.0 - (j + 0.5) / 64;  // rows top to bottom
      const double d = std::hypot(x - cx, y - cy) - r;
      sdf.field.push_back(float(d));
      image.field.push_back(float(std::clamp(0.5 - 64 * d, 0.0, 1.0)));  // an antialiased disc
    }
  FluidSettings s;
  s.resolution = {96, 96};
  s.size = {1.0, 1.0};
  s.obstacles = {sdf};
  EXPECT_NEAR(surfaceArea(FluidSolver<2>(s)) / (2 * kPi * r), 1.0, 1e-2);
  s.obstacles = {image};
  EXPECT_NEAR(surfaceArea(FluidSolver<2>(s)) / (2 * kPi * r), 1.0, 4e-2);
}
