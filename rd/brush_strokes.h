// Kim & Lin's painting interface (seed 001 sec. 6): brush strokes rasterised
// on the RD grid, their direction carried to every cell by fast extension
// velocities, so that each cell's anisotropy follows the nearest stroke.
//
// A stroke is a polyline (points in domain units) of a given width, or a grey
// image whose bright pixels are strokes. A polyline's direction is its
// tangent, from one point to the next (an angle in [-pi, pi], the xy plane);
// an image has no drawing order, so its direction is the tangent of the
// mask's structure tensor, known only up to pi.
#pragma once

#include <array>
#include <vector>

#include "core/grid.h"
#include "core/spatial_field.h"

namespace morphoflow {

struct BrushStroke {
  std::vector<std::array<double, 3>> points;  // domain units (z ignored in 2D); >= 2 for a polyline
  double width = 0.0;                         // domain units (0: one cell)
  SpatialField image;                         // or an image of strokes (luminance > 1/2 inside)
  bool isImage() const { return image.isImage(); }
};

template <int D>
struct PaintedStrokes {
  std::vector<uint8_t> under;     // 1 where a stroke covers the cell
  std::vector<double> distance;   // to the nearest stroke (its centre line), domain units
  std::vector<double> angle;      // the nearest stroke's direction, extended (radians)
};

// `size` is the domain's extent per axis; a periodic domain wraps strokes and
// distances. Throws std::invalid_argument when a stroke covers no cell.
template <int D>
PaintedStrokes<D> paintStrokes(const std::vector<BrushStroke>& strokes, const IVec<D>& cells,
                               const std::vector<double>& size, bool periodic);

// The cells under one stroke (1) and the rest (0).
template <int D>
std::vector<uint8_t> strokeCoverage(const BrushStroke& stroke, const IVec<D>& cells, const std::vector<double>& size,
                                    bool periodic);

}  // namespace morphoflow
