// Turns a 2D scalar field (or a z slice of a 3D one) into colormapped RGB,
// y up (the image's top row is the field's last row).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

struct FieldImageOptions {
  std::string colormap = "viridis";
  bool autoRange = true;   // min..max, or symmetric -m..m when `symmetric`
  bool symmetric = false;
  double range[2] = {0.0, 1.0};
  int slice = -1;          // 3D: z index (-1 = middle)
};

template <int D>
std::vector<uint8_t> fieldToRgb(const Grid<float, D>& field, const FieldImageOptions& options, int* width,
                                int* height);

}  // namespace morphoflow
