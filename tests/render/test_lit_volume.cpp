// The lit preview (render/lit_volume.h): the same bytes on any thread
// count, self-shadowing (the lit side of a ball brighter than its shadowed
// side), an exposure and extinction chosen from the data (a density scaled
// by 10 renders the same picture), the palette as the albedo, blackbody
// emission that reddens as it cools; and the legibility measures
// (render/legibility.h) on pictures whose answers are known.
#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "render/blackbody.h"
#include "render/legibility.h"
#include "render/lit_volume.h"
#include "render/volume_camera.h"

using namespace morphoflow;

namespace {

// A ball of radius r cells (a smooth edge over a cell) with a ripple along x
// of `ripple` relative amplitude.
Grid<float, 3> ball(int n, double r, double ripple = 0.0) {
  Grid<float, 3> g(IVec<3>{n, n, n}, 0.0f);
  for (size_t i = 0; i < g.size(); ++i) {
    const IVec<3> x = g.coord(i);
    double d2 = 0;
    for (int a = 0; a < 3; ++a) d2 += (x[a] + 0.5 - 0.5 * n) * (x[a] + 0.5 - 0.5 * n);
    const double inside = std::clamp(r - std::sqrt(d2) + 0.5, 0.0, 1.0);
    g[i] = float(inside * (1.0 + ripple * std::sin(0.9 * x[0]) * std::sin(0.9 * x[1])));
  }
  return g;
}

double luminance(const LitImage& img, size_t i) {
  return 0.2126 * img.rgb[3 * i] + 0.7152 * img.rgb[3 * i + 1] + 0.0722 * img.rgb[3 * i + 2];
}

}  // namespace

TEST(LitVolume, IsTheSameBytesOnOneThreadAndOnMany) {
  const Grid<float, 3> rho = ball(40, 14.0, 0.5);
  LitVolume v;
  v.density = &rho;
  v.shown = &rho;
  v.options.palette = namedPalette("magma");
  LitImage one, many;
  {
    ThreadLimit limit(1);
    one = renderLitVolume(v, 96);
  }
  {
    ThreadLimit limit(3);
    many = renderLitVolume(v, 96);
  }
  EXPECT_EQ(one.rgb, many.rgb);
  EXPECT_EQ(one.exposure, many.exposure);
}

// Seen from the camera, the ball's side toward the key light is brighter
// than the side away from it: the transmittance toward the light shadows.
TEST(LitVolume, TheSideTowardTheKeyIsBrighterThanTheShadowedSide) {
  const int n = 48, size = 128;
  const Grid<float, 3> rho = ball(n, 16.0);
  LitVolume v;
  v.density = &rho;
  const LitImage img = renderLitVolume(v, size);
  const VolumeCamera cam(rho.dims());
  const std::array<double, 3> key = keyLightDirection();
  // Points on the ball's surface toward and away from the light, in the picture.
  double lit = 0, shadowed = 0;
  for (const double sign : {1.0, -1.0}) {
    const V3 p =
        add(V3{0.5 * n, 0.5 * n, 0.5 * n}, scale(unit(add(scale(key, sign), scale(cam.towardEye, 1.2))), 15.0));
    double x, y;
    ASSERT_TRUE(cam.project(p, size, &x, &y));
    const size_t i = size_t(std::lround(y)) * size_t(size) + size_t(std::lround(x));
    EXPECT_GT(img.opacity[i], 0.9);
    (sign > 0 ? lit : shadowed) = luminance(img, i);
  }
  EXPECT_GT(lit, 1.5 * shadowed) << lit << " " << shadowed;
}

TEST(LitVolume, ExposureAndExtinctionFollowTheData) {
  Grid<float, 3> rho = ball(32, 11.0, 0.4);
  LitVolume v;
  v.density = &rho;
  const LitImage a = renderLitVolume(v, 64);
  for (size_t i = 0; i < rho.size(); ++i) rho[i] *= 10.0f;
  const LitImage b = renderLitVolume(v, 64);
  EXPECT_NEAR(b.extinction, 0.1 * a.extinction, 1e-6 * a.extinction);  // (the densities rounded to float)
  size_t differ = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) differ += std::abs(int(a.rgb[i]) - int(b.rgb[i])) > 1;
  EXPECT_EQ(differ, 0u);
  // Neither black nor blown out: the ball's median luminance is mid-grey.
  const Legibility m = measureLegibility(a.rgb, 64, 64);
  EXPECT_GT(m.medianLuminance, 0.25);
  EXPECT_LT(m.medianLuminance, 0.9);
}

// The palette colours the albedo: a field at the top of a red-to-blue
// gradient's range scatters blue, at its bottom red.
TEST(LitVolume, ThePaletteColoursTheAlbedo) {
  const Grid<float, 3> rho = ball(24, 8.0);
  for (const float t : {0.0f, 1.0f}) {
    Grid<float, 3> shown(rho.dims(), t);
    shown[0] = 1.0f - t;  // the range spans 0..1
    LitVolume v;
    v.density = &rho;
    v.shown = &shown;
    v.options.palette = Palette{{{255, 0, 0}, {0, 0, 255}}};
    const LitImage img = renderLitVolume(v, 48);
    const size_t centre = 24 * 48 + 24;
    EXPECT_EQ(img.rgb[3 * centre + 1], 0);
    const int lo = img.rgb[3 * centre + (t == 0 ? 2 : 0)], hi = img.rgb[3 * centre + (t == 0 ? 0 : 2)];
    EXPECT_GT(hi, 10 * lo + 10) << "t = " << t;  // red at the bottom of the range, blue at the top
  }
}

// Planck's colours: red at 1000 K, near white at 6500 K (D65's temperature),
// blue beyond; luminance 1 throughout.
TEST(Blackbody, ReddensAsItCoolsAndIsWhiteNearD65) {
  const auto lum = [](const std::array<double, 3>& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; };
  const std::array<double, 3> cool = blackbodyColour(1000), d65 = blackbodyColour(6504), hot = blackbodyColour(15000);
  EXPECT_GT(cool[0], 3 * cool[1]);
  EXPECT_LT(cool[2], 1e-3);
  EXPECT_NEAR(d65[0] / d65[1], 1.0, 0.06);
  EXPECT_NEAR(d65[2] / d65[1], 1.0, 0.06);
  EXPECT_GT(hot[2], hot[0]);
  for (const auto& c : {d65, hot}) EXPECT_NEAR(lum(c), 1.0, 1e-4);  // (the sRGB matrix's rounded digits)
}

// Emission from the temperature adds light: a hot ball is brighter than a
// cold one with the same density, and redder at a lower temperature.
TEST(LitVolume, BlackbodyEmissionFromTheTemperature) {
  const Grid<float, 3> rho = ball(24, 8.0);
  const size_t centre = 24 * 48 + 24;
  LitVolume v;
  v.density = &rho;
  const LitImage dark = renderLitVolume(v, 48);
  std::array<double, 2> redOverBlue{};
  for (const int k : {0, 1}) {
    const Grid<float, 3> t(rho.dims(), k == 0 ? 2.0f : 20.0f);  // 1300 K and 5800 K
    v.temperature = &t;
    v.emission = 4.0;
    const LitImage img = renderLitVolume(v, 48);
    EXPECT_LT(img.exposure, 0.5 * dark.exposure);  // brighter radiance, so a smaller exposure
    redOverBlue[size_t(k)] = double(img.rgb[3 * centre]) / std::max(1, int(img.rgb[3 * centre + 2]));
  }
  EXPECT_GT(redOverBlue[0], 2.0 * redOverBlue[1]);
}

// The legibility measures of pictures whose answers are known.
TEST(Legibility, MeasuresAFlatDiscAndAStripedOne) {
  const int w = 96, h = 96;
  double flat = 0;
  for (const bool striped : {false, true}) {
    std::vector<uint8_t> rgb(size_t(w) * h * 3, 15);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if ((x - 48) * (x - 48) + (y - 48) * (y - 48) < 30 * 30) {
          const uint8_t g = striped && (x / 4) % 2 ? 64 : 128;
          for (int k = 0; k < 3; ++k) rgb[(size_t(y) * w + size_t(x)) * 3 + size_t(k)] = g;
        }
    const Legibility m = measureLegibility(rgb, w, h);
    EXPECT_NEAR(double(m.plumePixels), M_PI * 30 * 30, 100.0);
    if (!striped) {
      EXPECT_NEAR(m.medianLuminance, 128.0 / 255.0, 1e-9);
      flat = m.bandContrast;  // only the disc's rim passes the band
      EXPECT_LT(flat, 0.15);
    } else {
      EXPECT_GT(m.bandContrast, 2.0 * flat);  // and 4-pixel stripes
    }
  }
}

// An obstacle is an opaque grey surface in front of the smoke: it hides the
// ball behind it, its side toward the key is brighter, and the exposure is
// the smoke's alone.
TEST(LitVolume, AnObstacleIsAnOpaqueGreySurfaceThatHidesTheSmoke) {
  const int n = 48, size = 128;
  const Grid<float, 3> rho = ball(n, 14.0);
  // A solid ball of radius 6 cells between the smoke and the camera, on a grid half as fine.
  const VolumeCamera cam(rho.dims());
  const V3 centre = add(V3{0.5 * n, 0.5 * n, 0.5 * n}, scale(cam.towardEye, 19.0));
  Grid<float, 3> solid(IVec<3>{n / 2, n / 2, n / 2}, 0.0f);
  for (size_t i = 0; i < solid.size(); ++i) {
    const IVec<3> x = solid.coord(i);
    double d2 = 0;
    for (int a = 0; a < 3; ++a) d2 += std::pow(2.0 * (x[a] + 0.5) - centre[size_t(a)], 2);
    solid[i] = d2 < 36.0 ? 1.0f : 0.0f;
  }
  LitVolume plain;
  plain.density = &rho;
  LitVolume with = plain;
  with.solid = &solid;
  const LitImage a = renderLitVolume(plain, size), b = renderLitVolume(with, size);
  double x, y;
  ASSERT_TRUE(cam.project(centre, size, &x, &y));
  const size_t i = size_t(std::lround(y)) * size_t(size) + size_t(std::lround(x));
  EXPECT_EQ(b.opacity[i], 1.0f);
  // Grey: the key's warmth only, unlike the smoke's colour there before.
  EXPECT_NEAR(double(b.rgb[3 * i]), double(b.rgb[3 * i + 2]), 40.0);
  EXPECT_NE(a.rgb[3 * i], b.rgb[3 * i]);
  // Its side toward the key light is the brighter.
  const std::array<double, 3> key = keyLightDirection();
  double lit = 0, dark = 0;
  for (const double sign : {1.0, -1.0}) {
    const V3 p = add(centre, scale(unit(add(scale(key, sign), scale(cam.towardEye, 1.5))), 5.5));
    ASSERT_TRUE(cam.project(p, size, &x, &y));
    (sign > 0 ? lit : dark) = luminance(b, size_t(std::lround(y)) * size_t(size) + size_t(std::lround(x)));
  }
  EXPECT_GT(lit, 1.3 * dark) << lit << " " << dark;
  // An obstacle that hides no smoke (above the ball in the picture) leaves the smoke's exposure as it was.
  const V3 above = add(V3{0.5 * n, 0.5 * n, 0.5 * n}, add(scale(cam.up, 20.0), scale(cam.towardEye, 8.0)));
  Grid<float, 3> aside(solid.dims(), 0.0f);
  for (size_t k = 0; k < aside.size(); ++k) {
    const IVec<3> x = aside.coord(k);
    double d2 = 0;
    for (int a2 = 0; a2 < 3; ++a2) d2 += std::pow(2.0 * (x[a2] + 0.5) - above[size_t(a2)], 2);
    aside[k] = d2 < 16.0 ? 1.0f : 0.0f;
  }
  with.solid = &aside;
  const LitImage c = renderLitVolume(with, size);
  EXPECT_EQ(a.exposure, c.exposure);
  // The obstacle keeps its brightness whatever the smoke's exposure: with a
  // dimmer smoke (an albedo through a dark palette) the picture's exposure
  // rises, the obstacle's pixels stay the same bytes.
  LitVolume dim = with;
  dim.shown = &rho;
  dim.options.palette = namedPalette("magma");
  dim.options.autoRange = false;
  dim.options.range[0] = 0.0, dim.options.range[1] = 4.0;  // the smoke's values low in the palette: dark
  const LitImage d = renderLitVolume(dim, size);
  EXPECT_GT(d.exposure, 1.5 * c.exposure);
  int same = 0, seen = 0;
  for (size_t k = 0; k < c.opacity.size(); ++k)
    if (c.opacity[k] == 1.0f && a.opacity[k] < 0.01f) {
      ++seen;
      same +=
          c.rgb[3 * k] == d.rgb[3 * k] && c.rgb[3 * k + 1] == d.rgb[3 * k + 1] && c.rgb[3 * k + 2] == d.rgb[3 * k + 2];
    }
  EXPECT_GT(seen, 10);
  EXPECT_EQ(same, seen);
  int grey = 0;
  for (size_t k = 0; k < c.opacity.size(); ++k) grey += c.opacity[k] == 1.0f && a.opacity[k] < 0.5f;
  EXPECT_GT(grey, 10) << "the obstacle aside is drawn";
}
