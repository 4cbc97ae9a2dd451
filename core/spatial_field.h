// SpatialField: a value that varies across the domain, given either as an
// Expression in the cell's position or as a grey image stretched over the
// domain. Scenes use it for parameter maps (seed 004 Table 1 notes a and b,
// seed 002 fig. 2-3), initial states and fixed regions (seed 004 fig. 20).
#pragma once

#include <string>
#include <vector>

#include "core/expression.h"
#include "core/grid.h"

namespace morphoflow {

struct SpatialField {
  std::string expression;          // used when `image` is empty
  // Image alternative: row-major grey pixels, top row first (the domain's top,
  // y = 1), bilinearly interpolated; luminance 0..1 maps to range[0]..range[1].
  int imageWidth = 0, imageHeight = 0;
  std::vector<float> image;
  double range[2] = {0.0, 1.0};
  bool isImage() const { return !image.empty(); }
};

// The variables an expression may use, in binding order:
//   x, y, z     cell centre as a fraction of the domain, in [0, 1] (z = 0.5 in 2D)
//   r, theta    distance from the domain centre (same units) and angle atan2(y - 1/2, x - 1/2)
//   i, j, k     integer cell index (k = 0 in 2D);  nx, ny, nz  cells per axis (nz = 1 in 2D)
const std::vector<std::string>& spatialFieldVariables();

// Throws ExpressionError for a malformed expression (use it to validate input).
Expression compileSpatialField(const std::string& expression);

// The field at every cell of a grid of `cells` (x fastest).
template <int D>
std::vector<double> sampleSpatialField(const SpatialField& field, const IVec<D>& cells);

}  // namespace morphoflow
