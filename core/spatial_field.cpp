#include "core/spatial_field.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

const std::vector<std::string>& spatialFieldVariables() {
  static const std::vector<std::string> v = {"x", "y", "z", "r", "theta", "i", "j", "k", "nx", "ny", "nz"};
  return v;
}

Expression compileSpatialField(const std::string& expression) {
  return Expression(expression, spatialFieldVariables());
}

namespace {
// Bilinear lookup at (u, v) in [0, 1]^2, v up; pixel centres at (p + 1/2) / size.
double sampleImage(const SpatialField& f, double u, double v) {
  const int w = f.imageWidth, h = f.imageHeight;
  double px = std::clamp(u * w - 0.5, 0.0, double(w - 1)), py = std::clamp((1.0 - v) * h - 0.5, 0.0, double(h - 1));
  int x0 = std::min(int(px), w - 1), y0 = std::min(int(py), h - 1);
  int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  double fx = px - x0, fy = py - y0;
  auto at = [&](int x, int y) { return double(f.image[size_t(y) * size_t(w) + size_t(x)]); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
}
}  // namespace

template <int D>
std::vector<double> sampleSpatialField(const SpatialField& field, const IVec<D>& cells) {
  size_t n = 1;
  for (int a = 0; a < D; ++a) n *= size_t(cells[a]);
  std::vector<double> out(n);
  const Expression e = field.isImage() ? Expression("0", {}) : compileSpatialField(field.expression);
  forEachCell<D>(cells, [&](const IVec<D>& c, size_t i) {
    double x = (c[0] + 0.5) / cells[0], y = (c[1] + 0.5) / cells[1];
    if (field.isImage()) {
      out[i] = field.range[0] + (field.range[1] - field.range[0]) * sampleImage(field, x, y);
      return;
    }
    double z = D == 3 ? (c[D - 1] + 0.5) / cells[D - 1] : 0.5;
    double v[11] = {x, y, z, std::hypot(x - 0.5, y - 0.5, D == 3 ? z - 0.5 : 0.0), std::atan2(y - 0.5, x - 0.5),
                    double(c[0]), double(c[1]), D == 3 ? double(c[D - 1]) : 0.0,
                    double(cells[0]), double(cells[1]), D == 3 ? double(cells[D - 1]) : 1.0};
    out[i] = e.evaluate(v);
  });
  return out;
}

template std::vector<double> sampleSpatialField<2>(const SpatialField&, const IVec<2>&);
template std::vector<double> sampleSpatialField<3>(const SpatialField&, const IVec<3>&);

}  // namespace morphoflow
