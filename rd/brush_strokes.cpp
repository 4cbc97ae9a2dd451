#include "rd/brush_strokes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "rd/fast_marching.h"
#include "rd/grid_difference.h"

namespace morphoflow {

namespace {

constexpr double kFar = std::numeric_limits<double>::infinity();

// Distance from p to the segment [a, b].
template <int D>
double segmentDistance(const Vec<D>& p, const Vec<D>& a, const Vec<D>& b) {
  const Vec<D> ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  const Vec<D> q = a + t * ab - p;
  return std::sqrt(glm::dot(q, q));
}

// The exact distance to a polyline for every cell within `reach` of it, and
// the direction (cos, sin of the tangent's xy angle) of the nearest segment.
template <int D>
void rasterisePolyline(const BrushStroke& s, const Grid<char, D>& shape, double h, double reach, bool periodic,
                       std::vector<double>* dist, std::vector<double>* cx, std::vector<double>* cy) {
  for (size_t q = 0; q + 1 < s.points.size(); ++q) {
    Vec<D> a, b;
    for (int k = 0; k < D; ++k) a[k] = s.points[q][size_t(k)], b[k] = s.points[q + 1][size_t(k)];
    const double tx = b[0] - a[0], ty = b[1] - a[1], tl = std::hypot(tx, ty);
    IVec<D> lo, hi;
    for (int k = 0; k < D; ++k) {
      lo[k] = int(std::floor((std::min(a[k], b[k]) - reach) / h - 0.5));
      hi[k] = int(std::ceil((std::max(a[k], b[k]) + reach) / h - 0.5));
    }
    const Grid<char, D> box(hi - lo + IVec<D>(1));
    for (size_t bi = 0; bi < box.size(); ++bi) {  // serial: near a wrap two box cells can be one grid cell
      IVec<D> c = lo + box.coord(bi);
      Vec<D> p;
      for (int k = 0; k < D; ++k) p[k] = (c[k] + 0.5) * h;  // unwrapped, so the segment's image across a wrap is found
      const double d = segmentDistance<D>(p, a, b);
      bool inside = d <= reach;
      for (int k = 0; k < D && inside; ++k) {
        const int n = shape.dim(k);
        if (c[k] < 0 || c[k] >= n) {
          inside = periodic;
          c[k] = ((c[k] % n) + n) % n;
        }
      }
      if (!inside) continue;
      const size_t i = shape.index(c);
      if (d < (*dist)[i]) {
        (*dist)[i] = d;
        (*cx)[i] = tl > 0 ? tx / tl : 1.0;
        (*cy)[i] = tl > 0 ? ty / tl : 0.0;
      }
    }
  }
}

// An image stroke's mask, and the doubled tangent angle (cos 2a, sin 2a) of
// its structure tensor smoothed over 5 cells; zero where the mask is flat.
template <int D>
void rasteriseImage(const BrushStroke& s, const Grid<char, D>& shape, bool periodic, std::vector<double>* dist,
                    std::vector<double>* cx, std::vector<double>* cy) {
  const std::vector<double> v = sampleSpatialField<D>(s.image, shape.dims());
  Grid<double, D> mask(shape.dims());
  for (size_t i = 0; i < v.size(); ++i) mask[i] = v[i] > 0.5 * (s.image.range[0] + s.image.range[1]) ? 1.0 : 0.0;
  const size_t n = mask.size();
  std::vector<double> jxx(n), jxy(n), jyy(n);
  forEachCell<D>(shape.dims(), [&](const IVec<D>& c, size_t i) {
    const double gx = centralDifference<D>(mask, c, 0, periodic), gy = centralDifference<D>(mask, c, 1, periodic);
    jxx[i] = gx * gx, jxy[i] = gx * gy, jyy[i] = gy * gy;
  });
  forEachCell<D>(shape.dims(), [&](const IVec<D>& c, size_t i) {
    if (mask[i] == 0.0) return;
    double sxx = 0, sxy = 0, syy = 0;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        IVec<D> o = c;
        o[0] += dx, o[1] += dy;
        bool inside = true;
        for (int k = 0; k < 2; ++k) {
          if (o[k] >= 0 && o[k] < shape.dim(k)) continue;
          if (periodic) o[k] = (o[k] + shape.dim(k)) % shape.dim(k);
          else inside = false;
        }
        if (!inside) continue;
        const size_t j = shape.index(o);
        sxx += jxx[j], sxy += jxy[j], syy += jyy[j];
      }
    // The gradient's orientation is 1/2 atan2(2 Jxy, Jxx - Jyy); the tangent is normal to it.
    const double ex = -(sxx - syy), ey = -2.0 * sxy, len = std::hypot(ex, ey);
    (*dist)[i] = 0.0;
    (*cx)[i] = len > 0 ? ex / len : 0.0;
    (*cy)[i] = len > 0 ? ey / len : 0.0;
  });
}

// One stroke on the grid: the cells under it, and the known distance and
// direction near it (doubled angles when the strokes are known only up to pi).
struct Raster {
  std::vector<uint8_t> under;
  std::vector<double> dist, cx, cy;
};

template <int D>
Raster rasteriseStroke(const BrushStroke& s, size_t index, const Grid<char, D>& shape, double h, bool periodic,
                       bool doubled) {
  const size_t n = shape.size();
  Raster r{std::vector<uint8_t>(n, 0), std::vector<double>(n, kFar), std::vector<double>(n, 0.0),
           std::vector<double>(n, 0.0)};
  size_t covered = 0;
  if (s.isImage()) {
    rasteriseImage<D>(s, shape, periodic, &r.dist, &r.cx, &r.cy);
    for (size_t i = 0; i < n; ++i) covered += r.under[i] = r.dist[i] == 0.0;
  } else {
    // Under the stroke: within half its width, and at least the cells nearest its centre line.
    const double radius = std::max(0.5 * s.width, 0.5 * h * std::sqrt(double(D)));
    rasterisePolyline<D>(s, shape, h, radius + h, periodic, &r.dist, &r.cx, &r.cy);
    for (size_t i = 0; i < n; ++i) {
      covered += r.under[i] = r.dist[i] <= radius;
      if (doubled) {  // a polyline in an image's company is known only up to pi, as the image is
        const double x = r.cx[i], y = r.cy[i];
        r.cx[i] = x * x - y * y, r.cy[i] = 2.0 * x * y;
      }
    }
  }
  if (covered == 0) throw std::invalid_argument("stroke " + std::to_string(index) + " covers no cell of the grid");
  return r;
}

}  // namespace

template <int D>
std::vector<uint8_t> strokeCoverage(const BrushStroke& stroke, const IVec<D>& cells, const std::vector<double>& size,
                                    bool periodic) {
  return rasteriseStroke<D>(stroke, 0, Grid<char, D>(cells), size[0] / cells[0], periodic, stroke.isImage()).under;
}

template <int D>
PaintedStrokes<D> paintStrokes(const std::vector<BrushStroke>& strokes, const IVec<D>& cells,
                               const std::vector<double>& size, bool periodic) {
  const Grid<char, D> shape(cells);
  const size_t n = shape.size();
  const double h = size[0] / cells[0];
  const bool doubled = std::any_of(strokes.begin(), strokes.end(), [](const BrushStroke& s) { return s.isImage(); });
  std::vector<double> dist(n, kFar), cx(n, 0.0), cy(n, 0.0);
  std::vector<uint8_t> under(n, 0);
  for (size_t k = 0; k < strokes.size(); ++k) {
    const Raster r = rasteriseStroke<D>(strokes[k], k, shape, h, periodic, doubled);
    for (size_t i = 0; i < n; ++i) {
      under[i] |= r.under[i];
      if (r.dist[i] < dist[i]) dist[i] = r.dist[i], cx[i] = r.cx[i], cy[i] = r.cy[i];
    }
  }
  // Every cell of known distance seeds the march; the direction is extended along its characteristics.
  MarchingSeeds seeds;
  seeds.values.resize(2);
  for (size_t i = 0; i < n; ++i)
    if (dist[i] < kFar && (cx[i] != 0.0 || cy[i] != 0.0)) {
      seeds.cells.push_back(i);
      seeds.distance.push_back(dist[i]);
      seeds.values[0].push_back(cx[i]);
      seeds.values[1].push_back(cy[i]);
    }
  if (seeds.cells.empty()) throw std::invalid_argument("the strokes have no direction (an image stroke needs edges)");
  MarchingResult m = fastMarch<D>(cells, h, periodic, seeds);
  PaintedStrokes<D> out;
  out.under = std::move(under);
  out.distance = std::move(m.distance);
  out.angle.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (out.under[i]) out.distance[i] = std::min(out.distance[i], dist[i]);
    const double a = std::atan2(m.values[1][i], m.values[0][i]);
    out.angle[i] = doubled ? 0.5 * a : a;
  }
  return out;
}

template std::vector<uint8_t> strokeCoverage<2>(const BrushStroke&, const IVec<2>&, const std::vector<double>&, bool);
template std::vector<uint8_t> strokeCoverage<3>(const BrushStroke&, const IVec<3>&, const std::vector<double>&, bool);
template PaintedStrokes<2> paintStrokes<2>(const std::vector<BrushStroke>&, const IVec<2>&, const std::vector<double>&,
                                           bool);
template PaintedStrokes<3> paintStrokes<3>(const std::vector<BrushStroke>&, const IVec<3>&, const std::vector<double>&,
                                           bool);

}  // namespace morphoflow
