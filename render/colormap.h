// Palettes: a scalar in [0, 1] to 8-bit RGB by linear interpolation between
// evenly spaced colour stops. Named maps are matplotlib's perceptual viridis,
// magma and inferno (stops every 1/8), Moreland's diverging coolwarm and
// grayscale; a scene may instead give its own gradient of stops.
// "red-green" is not a scalar palette: it shows two species at once, the first
// in red and the second in green (seed 002, fig. 1); see twoFieldsToRgb.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace morphoflow {

using Rgb8 = std::array<uint8_t, 3>;

struct Palette {
  std::vector<Rgb8> stops;  // at least two
  // t is clamped to [0, 1]; a non-finite t shows as the first stop.
  Rgb8 operator()(double t) const;
};

inline constexpr const char* kTwoSpeciesPalette = "red-green";

// Scalar palettes by name, then the two-species palette.
std::vector<std::string> colormapNames();
// A scalar palette by name (grayscale for an unknown or the two-species name).
Palette namedPalette(const std::string& name);
// An 8-bit sRGB channel as linear light in [0, 1] (IEC 61966-2-1), as
// renderers' colour attributes expect.
inline float srgbToLinear(uint8_t c) {
  const double v = c / 255.0;
  return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}
// "#rrggbb" (or "rrggbb") to a colour; false when malformed.
bool parseHexColour(const std::string& text, Rgb8* colour);

}  // namespace morphoflow
