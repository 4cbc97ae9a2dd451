// Turns a 2D scalar field (or a z slice of a 3D one) into RGB through a
// palette, y up (the image's top row is the field's last row).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/grid.h"
#include "render/colormap.h"

namespace morphoflow {

struct FieldImageOptions {
  Palette palette = namedPalette("viridis");
  bool autoRange = true;   // min..max, or symmetric -m..m when `symmetric`
  bool symmetric = false;
  double range[2] = {0.0, 1.0};
  int slice = -1;          // 3D: z index (-1 = middle)
};

// The value range mapped to [0, 1]: fixed, or the finite min..max of the n
// values (centred on 0 when symmetric).
std::array<double, 2> valueRange(const float* values, size_t n, const FieldImageOptions& options);

// How many of the n values lie outside [lo, hi] (drawn at the range's ends).
size_t countOutside(const float* values, size_t n, double lo, double hi);

// Nearest-neighbour enlargement by the smallest whole factor that makes the
// image at least `minWidth` pixels wide (cells stay crisp squares).
std::vector<uint8_t> upscaleToWidth(const std::vector<uint8_t>& rgb, int* width, int* height, int minWidth);

template <int D>
std::vector<uint8_t> fieldToRgb(const Grid<float, D>& field, const FieldImageOptions& options, int* width,
                                int* height);

// Seed 002's view of two species: `red` in the red channel and `green` in the
// green one, each scaled to its own range (automatic, or options.range for both).
template <int D>
std::vector<uint8_t> twoFieldsToRgb(const Grid<float, D>& red, const Grid<float, D>& green,
                                    const FieldImageOptions& options, int* width, int* height);

}  // namespace morphoflow
