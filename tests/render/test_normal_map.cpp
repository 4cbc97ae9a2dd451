// Normal maps of a height field (seed 000 fig. 7): a plane's normal exactly,
// a sine's normals against the analytic ones, seamless across a periodic
// wrap, and the OpenGL encoding (green up the image).
#include <gtest/gtest.h>

#include <cmath>

#include "render/normal_map.h"

using namespace morphoflow;

TEST(NormalMap, APlaneHasOneNormalEverywhereIncludingItsEdges) {
  Grid<float, 2> h(IVec<2>(16, 8));
  for (size_t i = 0; i < h.size(); ++i) h[i] = 0.01f * float(h.coord(i)[0]) + 0.02f * float(h.coord(i)[1]);
  const std::vector<float> n = surfaceNormals(h, {3.0, false});
  const double len = std::sqrt(0.03 * 0.03 + 0.06 * 0.06 + 1.0);
  for (size_t i = 0; i < h.size(); ++i) {
    EXPECT_NEAR(n[3 * i], -0.03 / len, 1e-6);
    EXPECT_NEAR(n[3 * i + 1], -0.06 / len, 1e-6);
    EXPECT_NEAR(n[3 * i + 2], 1.0 / len, 1e-6);
  }
}

TEST(NormalMap, SineMatchesTheAnalyticNormalAndIsSeamless) {
  const int n = 64;
  const double k = 2.0 * M_PI / n, s = 5.0;
  Grid<float, 2> h(IVec<2>(n, n));
  for (size_t i = 0; i < h.size(); ++i) h[i] = float(0.5 + 0.5 * std::sin(k * (h.coord(i)[0] + 0.5)));
  const std::vector<float> nm = surfaceNormals(h, {s, true});
  for (int x = 0; x < n; ++x) {
    const double slope = 0.5 * k * std::cos(k * (x + 0.5)), len = std::sqrt(s * s * slope * slope + 1.0);
    const size_t i = 3 * h.index(IVec<2>(x, 7));
    EXPECT_NEAR(nm[i], -s * slope / len, 2e-3) << x;  // central differences: O(k^2) relative
    EXPECT_NEAR(nm[i + 1], 0.0, 1e-7);
  }
  // Periodic: the first column's normal is its neighbours' mirror, as inside the tile.
  const size_t first = 3 * h.index(IVec<2>(0, 3)), last = 3 * h.index(IVec<2>(n - 1, 3));
  EXPECT_NEAR(nm[first], nm[last], 1e-6);
}

TEST(NormalMap, OpenGLConventionGreenPointsUpTheImage) {
  // Height rising with y: the surface tilts towards -y, so green < 128; rows are flipped (top row = last grid row).
  Grid<float, 2> h(IVec<2>(4, 4));
  for (size_t i = 0; i < h.size(); ++i) h[i] = 0.1f * float(h.coord(i)[1]);
  const std::vector<uint8_t> rgb = normalMapRgb(h, {1.0, false});
  for (size_t p = 0; p < 16; ++p) {
    EXPECT_EQ(rgb[3 * p], 128);
    EXPECT_LT(rgb[3 * p + 1], 128);
    EXPECT_GT(rgb[3 * p + 2], 250);
  }
  Grid<float, 2> bump(IVec<2>(3, 3));
  bump(IVec<2>(1, 2)) = 1.0f;  // a bump in the top row: the middle cell of row 1 faces down (-y)
  const std::vector<uint8_t> b = normalMapRgb(bump, {1.0, false});
  EXPECT_LT(b[3 * (3 * 1 + 1) + 1], 128);  // image row 1 = grid row 1
  EXPECT_EQ(b[3 * (3 * 1 + 1)], 128);
}
