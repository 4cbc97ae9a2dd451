// Tangent-space normal maps of a pattern read as a height field (seed 000
// fig. 7's bump-mapped textures): n = normalize(-s dh/dx, -s dh/dy, 1), h the
// field mapped to [0, 1] by the frame's value range, derivatives per cell by
// central differences (wrapped on periodic axes, so tiles stay seamless;
// one-sided at walls), s the strength. OpenGL convention: +y (green) is up
// the image, and RGB = (n + 1) / 2.
#pragma once

#include <cstdint>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

struct NormalMapOptions {
  double strength = 1.0;   // height units (0..1 over the value range) per cell
  bool periodic = false;
};

// The unit normals, three per cell, in grid order (x fastest, y up).
std::vector<float> surfaceNormals(const Grid<float, 2>& height, const NormalMapOptions& options);

// The normals as 8-bit RGB, row-major with the top image row the grid's last row (as frames are).
std::vector<uint8_t> normalMapRgb(const Grid<float, 2>& height, const NormalMapOptions& options);

}  // namespace morphoflow
