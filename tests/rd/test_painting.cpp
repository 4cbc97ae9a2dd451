// Kim & Lin's painting interface (seed 001 sec. 6): fast marching distances
// against the exact Euclidean distance (first-order convergence), extension
// values constant along the normals of a straight interface, and the painted
// direction following a stroke's tangent, in 2D, 3D and across a periodic wrap.
#include <gtest/gtest.h>

#include <cmath>

#include "rd/brush_strokes.h"
#include "rd/fast_marching.h"

using namespace morphoflow;

namespace {

// The largest |distance - exact| over a square grid of n cells on [0, 1]^2
// seeded with the single cell nearest `p` (at its exact distance).
double pointSourceError(int n) {
  const IVec<2> cells(n, n);
  const double h = 1.0 / n;
  const int ci = n / 3, cj = n / 2;
  const double px = (ci + 0.5) * h, py = (cj + 0.5) * h;
  MarchingSeeds seeds;
  seeds.cells = {size_t(cj) * size_t(n) + size_t(ci)};
  seeds.distance = {0.0};
  const MarchingResult m = fastMarch<2>(cells, h, false, seeds);
  double err = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      err = std::max(err, std::abs(m.distance[size_t(j * n + i)] - std::hypot((i + 0.5) * h - px, (j + 0.5) * h - py)));
  return err;
}

// Cells within 1.5 h of the line through `o` along unit `t`, seeded with their
// exact distance and, as the value to extend, the position of their foot
// point along the line.
MarchingSeeds lineSeeds(int n, double ox, double oy, double tx, double ty) {
  const double h = 1.0 / n;
  MarchingSeeds s;
  s.values.resize(1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = (i + 0.5) * h - ox, y = (j + 0.5) * h - oy;
      const double d = std::abs(x * ty - y * tx);
      if (d > 1.5 * h) continue;
      s.cells.push_back(size_t(j * n + i));
      s.distance.push_back(d);
      s.values[0].push_back(x * tx + y * ty);
    }
  return s;
}

double angleDifference(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * M_PI)); }

}  // namespace

TEST(FastMarching, DistanceToAPointConvergesAtFirstOrder) {
  const double e64 = pointSourceError(64), e128 = pointSourceError(128), e256 = pointSourceError(256);
  // First-order upwind from a point: the error shrinks with h (up to log h), and stays a few cells' worth.
  EXPECT_LT(e128, 0.75 * e64);
  EXPECT_LT(e256, 0.75 * e128);
  EXPECT_LT(e256, 3.0 / 256);
  EXPECT_GT(e256, 0.0);
}

TEST(FastMarching, DistanceToALineAndExtensionAlongItsNormals) {
  for (int n : {64, 128}) {
    const double h = 1.0 / n, tx = std::cos(0.5), ty = std::sin(0.5), ox = 0.4, oy = 0.45;
    const MarchingResult m = fastMarch<2>(IVec<2>(n, n), h, false, lineSeeds(n, ox, oy, tx, ty));
    double errD = 0, errV = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = (i + 0.5) * h - ox, y = (j + 0.5) * h - oy, s = x * tx + y * ty;
        const double fx = ox + s * tx, fy = oy + s * ty;  // the foot point must be on the seeded part of the line
        if (std::min(fx, fy) < 2 * h || std::max(fx, fy) > 1 - 2 * h) continue;
        errD = std::max(errD, std::abs(m.distance[size_t(j * n + i)] - std::abs(x * ty - y * tx)));
        // The extended value is the foot point's: constant along each normal of the line.
        errV = std::max(errV, std::abs(m.values[0][size_t(j * n + i)] - (x * tx + y * ty)));
      }
    EXPECT_LT(errD, 2.0 * h) << n;
    EXPECT_LT(errV, 3.0 * h) << n;
  }
}

TEST(FastMarching, ThreeDimensionsAndPeriodicWrap) {
  const int n = 32;
  const double h = 1.0 / n;
  MarchingSeeds seeds;
  seeds.cells = {0};  // the corner cell: on a periodic grid its nearest images surround every corner
  seeds.distance = {0.0};
  const MarchingResult m = fastMarch<3>(IVec<3>(n, n, n), h, true, seeds);
  const Grid<char, 3> shape(IVec<3>(n, n, n));
  double err = 0;
  for (size_t i = 0; i < shape.size(); ++i) {
    const IVec<3> c = shape.coord(i);
    double r2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = std::min(c[a], n - c[a]) * h;
      r2 += d * d;
    }
    err = std::max(err, std::abs(m.distance[i] - std::sqrt(r2)));
  }
  EXPECT_LT(err, 4.0 * h);
  EXPECT_DOUBLE_EQ(m.distance[shape.index(IVec<3>(n - 1, 0, 0))], h);  // across the wrap
}

TEST(BrushStrokes, DirectionFollowsTheTangent) {
  const int n = 128;
  const IVec<2> cells(n, n);
  // A counter-clockwise circle of radius 0.25 about the centre.
  BrushStroke circle;
  circle.width = 0.02;
  for (int q = 0; q <= 96; ++q) {
    const double a = 2.0 * M_PI * q / 96;
    circle.points.push_back({0.5 + 0.25 * std::cos(a), 0.5 + 0.25 * std::sin(a), 0.0});
  }
  const PaintedStrokes<2> p = paintStrokes<2>({circle}, cells, {1.0, 1.0}, false);
  const double h = 1.0 / n;
  double worst = 0;
  size_t under = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t c = size_t(j * n + i);
      const double x = (i + 0.5) * h - 0.5, y = (j + 0.5) * h - 0.5, r = std::hypot(x, y);
      EXPECT_NEAR(p.distance[c], std::abs(r - 0.25), 2.0 * h);
      under += p.under[c];
      if (p.under[c]) {
        EXPECT_LE(std::abs(r - 0.25), 0.01 + 2e-4) << i << "," << j;  // half the width, plus the chords' sag
      }
      if (r < 0.1 || r > 0.4) continue;  // near the centre the normals meet; beyond 0.4 they reach the walls
      worst = std::max(worst, angleDifference(p.angle[c], std::atan2(y, x) + 0.5 * M_PI));
    }
  EXPECT_LT(worst, 0.1);
  EXPECT_NEAR(double(under), 2.0 * M_PI * 0.25 * 0.02 / (h * h), 0.15 * 2.0 * M_PI * 0.25 * 0.02 / (h * h));
}

TEST(BrushStrokes, DrawingOrderSetsTheSenseAndWrapsOnPeriodicDomains) {
  const IVec<2> cells(64, 64);
  BrushStroke right, left;
  right.points = {{0.8, 0.5, 0.0}, {1.0, 0.5, 0.0}};  // ends on the wrap
  left.points = {{0.9, 0.3, 0.0}, {0.1, 0.3, 0.0}};
  const PaintedStrokes<2> pr = paintStrokes<2>({right}, cells, {1.0, 1.0}, true);
  const PaintedStrokes<2> pl = paintStrokes<2>({left}, cells, {1.0, 1.0}, false);
  for (size_t i = 0; i < pr.angle.size(); ++i) {
    ASSERT_LT(angleDifference(pr.angle[i], 0.0), 1e-12);
    ASSERT_LT(angleDifference(pl.angle[i], M_PI), 1e-12);
  }
  // Periodic: the first cell (x = h/2) is half a cell past the stroke's end at x = 1, across the wrap.
  EXPECT_NEAR(pr.distance[size_t(32 * 64 + 0)], std::hypot(0.5 / 64, 0.5 / 64), 1e-12);
  EXPECT_NEAR(pr.distance[size_t(32 * 64 + 63)], 0.5 / 64, 1e-12);
}

TEST(BrushStrokes, AnImageStrokeGivesItsOrientation) {
  // A diagonal bar 6 pixels wide: its orientation is pi/4 (mod pi) along the bar and beside it.
  const int w = 128;
  BrushStroke s;
  s.image.imageWidth = s.image.imageHeight = w;
  s.image.image.assign(size_t(w * w), 0.0f);
  for (int r = 0; r < w; ++r)
    for (int c = 0; c < w; ++c)
      if (std::abs(r - (w - 1 - c)) <= 3) s.image.image[size_t(r * w + c)] = 1.0f;  // top row first: y = 1 - r/w
  const PaintedStrokes<2> p = paintStrokes<2>({s}, IVec<2>(w, w), {1.0, 1.0}, false);
  double worst = 0;
  for (int j = 20; j < w - 20; ++j)
    for (int i = 20; i < w - 20; ++i)
      worst = std::max(worst, angleDifference(2.0 * p.angle[size_t(j * w + i)], 0.5 * M_PI));
  EXPECT_LT(worst, 0.05);
}

TEST(BrushStrokes, ThreeDimensionalStrokeUsesItsXYDirection) {
  BrushStroke s;
  s.points = {{0.2, 0.2, 0.5}, {0.8, 0.8, 0.5}};
  const PaintedStrokes<3> p = paintStrokes<3>({s}, IVec<3>(24, 24, 24), {1.0, 1.0, 1.0}, false);
  for (double a : p.angle) ASSERT_LT(angleDifference(a, 0.25 * M_PI), 1e-12);
  // A cell centred over the line, half a cell below it: exact near the stroke.
  const Grid<char, 3> shape(IVec<3>(24, 24, 24));
  EXPECT_NEAR(p.distance[shape.index(IVec<3>(11, 11, 11))], 0.5 / 24, 1e-12);
}
