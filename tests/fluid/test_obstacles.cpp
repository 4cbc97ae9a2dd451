// Obstacles: shapes rasterise to the right area/volume, and no fluid flows
// through them.
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/fluid_solver.h"
#include "fluid/obstacle.h"

using namespace morphoflow;

namespace {
const double kPi = 3.14159265358979323846;
}

TEST(Obstacles, CircleAndSphereRasteriseToTheirMeasure) {
  ObstacleSpec c;
  c.shape = ObstacleShape::Circle;
  c.center = {0.5, 0.5, 0};
  c.radius = 0.3;
  auto m2 = solidMask<2>({c}, IVec<2>(200, 200), 1.0 / 200);
  double area = 0;
  for (size_t i = 0; i < m2.size(); ++i) area += m2[i];
  EXPECT_NEAR(area / (200.0 * 200.0), kPi * 0.09, 0.01 * kPi * 0.09);

  ObstacleSpec s = c;
  s.shape = ObstacleShape::Sphere;
  s.center = {0.5, 0.5, 0.5};
  auto m3 = solidMask<3>({s}, IVec<3>(64, 64, 64), 1.0 / 64);
  double vol = 0;
  for (size_t i = 0; i < m3.size(); ++i) vol += m3[i];
  EXPECT_NEAR(vol / (64.0 * 64 * 64), 4.0 / 3.0 * kPi * 0.027, 0.03 * 4.0 / 3.0 * kPi * 0.027);
}

TEST(Obstacles, BoxImageAndSdfMasks) {
  ObstacleSpec b;
  b.shape = ObstacleShape::Box;
  b.center = {0.5, 0.25, 0};
  b.halfSize = {0.25, 0.125, 0};
  auto m = solidMask<2>({b}, IVec<2>(64, 64), 1.0 / 64);
  double area = 0;
  for (size_t i = 0; i < m.size(); ++i) area += m[i];
  EXPECT_EQ(area, 32.0 * 16.0);

  // An image whose left half is white: the left half of the domain is solid.
  ObstacleSpec img;
  img.shape = ObstacleShape::Image;
  img.fieldWidth = 8;
  img.fieldHeight = 4;
  img.field.assign(32, 0.0f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.field[size_t(y * 8 + x)] = 1.0f;
  auto mi = solidMask<2>({img}, IVec<2>(32, 16), 1.0 / 32);
  EXPECT_EQ(mi(IVec<2>(2, 8)), 1);
  EXPECT_EQ(mi(IVec<2>(29, 8)), 0);

  // A signed-distance field of a circle reproduces the circle.
  ObstacleSpec sdf;
  sdf.shape = ObstacleShape::Sdf;
  sdf.fieldWidth = sdf.fieldHeight = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      double px = (x + 0.5) / 64, py = 1.0 - (y + 0.5) / 64;
      sdf.field.push_back(float(std::hypot(px - 0.3, py - 0.6) - 0.2));
    }
  ObstacleSpec circle;
  circle.center = {0.3, 0.6, 0};
  circle.radius = 0.2;
  auto ms = solidMask<2>({sdf}, IVec<2>(64, 64), 1.0 / 64);
  auto mc = solidMask<2>({circle}, IVec<2>(64, 64), 1.0 / 64);
  int differ = 0;
  for (size_t i = 0; i < ms.size(); ++i) differ += ms[i] != mc[i];
  EXPECT_LT(differ, 8);  // only cells within rounding of the surface
}

// No velocity through a staircase obstacle's cells' faces, nor through a cut
// obstacle's closed faces; what enters at the inflow leaves at the outflow.
TEST(Obstacles, NoFlowThroughObstacles) {
  for (ObstacleBoundary boundary : {ObstacleBoundary::Voxel, ObstacleBoundary::Cut}) {
    FluidSettings s;
    s.resolution = {96, 48};
    s.size = {2.0, 1.0};
    s.viscosity = 1e-2;
    s.boundaries.sides[0].kind = BoundaryKind::Inflow;
    s.boundaries.sides[1].kind = BoundaryKind::Outflow;
    ObstacleSpec o;
    o.center = {0.5, 0.5, 0};
    o.radius = 0.15;
    o.boundary = boundary;
    s.obstacles.push_back(o);
    FluidSolver<2> f(s);
    for (int i = 0; i < 60; ++i) f.step(0.02);
    const auto& solid = f.solid();
    size_t closed = 0;
    for (int a = 0; a < 2; ++a)
      for (size_t i = 0; i < f.velocity()[a].size(); ++i) {
        const IVec<2> k = f.velocity()[a].coord(i), lo = k - unitVector<2>(a);
        const bool solidFace = boundary == ObstacleBoundary::Voxel
                                   ? (k[a] < s.resolution[size_t(a)] && solid(k)) || (lo[a] >= 0 && solid(lo))
                                   : f.constraints().open[a][i] == 0.0f;
        if (!solidFace) continue;
        ++closed;
        EXPECT_EQ(f.velocity()[a][i], 0.0f);
      }
    EXPECT_GT(closed, 150u);
    double in = 0, out = 0;
    for (int j = 0; j < 48; ++j) {
      in += f.velocity()[0](IVec<2>(0, j));
      out += f.velocity()[0](IVec<2>(96, j));
    }
    EXPECT_NEAR(out, in, 1e-4 * in);
    EXPECT_NEAR(in / 48, 1.0, 0.01);  // the mean inflow velocity
  }
}
