// How well a rendered element reads: measures of an 8-bit sRGB picture of
// a plume over a plain background, taken over the plume's pixels (those
// whose colour differs from the background's by more than kPlumeStep in a
// channel; the background is the commonest colour of the picture's border).
//   median luminance   Rec. 709 luminance of the encoded values, 0-1
//   band contrast      the standard deviation of the band-passed luminance
//                      (a 3x3 box blur minus a 13x13 box blur, over the
//                      whole picture, edges clamped) over the mean luminance
// A pattern that reaches the picture raises the band contrast above that of
// the same smoke without it (docs/vfx.md, "Legibility").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace morphoflow {

inline constexpr int kPlumeStep = 3;

struct Legibility {
  size_t plumePixels = 0;
  double plumeFraction = 0.0;  // of the picture
  double medianLuminance = 0.0;
  double bandContrast = 0.0;
};

// `rgb`: width x height x 3 bytes, top row first.
Legibility measureLegibility(const std::vector<uint8_t>& rgb, int width, int height);

}  // namespace morphoflow
