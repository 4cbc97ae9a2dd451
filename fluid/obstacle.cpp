#include "fluid/obstacle.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "fluid/obstacle_shape.h"

namespace morphoflow {

namespace {
// Bilinear sample of the spec's 2D field at normalised (s, t) in [0, 1]^2.
double sampleField(const ObstacleSpec& o, double s, double t) {
  double gx = std::clamp(s * o.fieldWidth - 0.5, 0.0, double(o.fieldWidth - 1));
  double gy = std::clamp(t * o.fieldHeight - 0.5, 0.0, double(o.fieldHeight - 1));
  int x0 = std::min(int(gx), std::max(o.fieldWidth - 2, 0));
  int y0 = std::min(int(gy), std::max(o.fieldHeight - 2, 0));
  int x1 = std::min(x0 + 1, o.fieldWidth - 1), y1 = std::min(y0 + 1, o.fieldHeight - 1);
  double fx = gx - x0, fy = gy - y0;
  auto at = [&](int x, int y) { return double(o.field[size_t(y) * size_t(o.fieldWidth) + size_t(x)]); };
  double a = at(x0, y0) + fx * (at(x1, y0) - at(x0, y0));
  double b = at(x0, y1) + fx * (at(x1, y1) - at(x0, y1));
  return a + fy * (b - a);
}
}  // namespace

double obstacleDistance(const ObstacleSpec& o, const double* x, int dims, const double* size) {
  switch (o.shape) {
    case ObstacleShape::Image: {
      // Image rows run top to bottom; world y runs bottom to top.
      double v = sampleField(o, x[0] / size[0], 1.0 - x[1] / size[1]);
      bool solid = o.invert ? v <= o.threshold : v > o.threshold;
      return solid ? -1.0 : 1.0;
    }
    case ObstacleShape::Sdf:
      return sampleField(o, x[0] / size[0], 1.0 - x[1] / size[1]);
    default: {  // circle, sphere, box: kernels/obstacle_shape.inc, in the body's frame
      const double wrap[3] = {o.wrap[0] ? 1.0 : 0.0, o.wrap[1] ? 1.0 : 0.0, o.wrap[2] ? 1.0 : 0.0};
      double q[3];
      obstacle_shape::osBodyFrame(dims, x, o.center.data(), size, wrap, o.orientation.data(), q);
      return obstacle_shape::osShapeDistance(int(o.shape), dims, q, o.radius, o.halfSize.data());
    }
  }
}

namespace {
// fn(i, d) for every cell i of the grid, d the obstacles' least distance at its centre.
template <int D, class Fn>
void eachCellDistance(const std::vector<ObstacleSpec>& obstacles, const IVec<D>& cells, double h, Fn&& fn) {
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells[a] * h;
  forEachCell<D>(cells, [&](const IVec<D>& c, size_t i) {
    double x[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) x[a] = (c[a] + 0.5) * h;
    double d = 1e300;
    for (const ObstacleSpec& o : obstacles) d = std::min(d, obstacleDistance(o, x, D, size));
    fn(i, d);
  });
}
}  // namespace

template <int D>
Grid<uint8_t, D> solidMask(const std::vector<ObstacleSpec>& obstacles, const IVec<D>& cells, double h) {
  Grid<uint8_t, D> mask(cells, 0);
  eachCellDistance<D>(obstacles, cells, h, [&](size_t i, double d) { mask[i] = d < 0 ? 1 : 0; });
  return mask;
}

template <int D>
Grid<float, D> solidOccupancy(const std::vector<ObstacleSpec>& obstacles, const IVec<D>& cells, double h) {
  Grid<float, D> occupancy(cells, 0.0f);
  eachCellDistance<D>(obstacles, cells, h,
                      [&](size_t i, double d) { occupancy[i] = float(std::clamp(0.5 - d / h, 0.0, 1.0)); });
  return occupancy;
}

template Grid<float, 2> solidOccupancy<2>(const std::vector<ObstacleSpec>&, const IVec<2>&, double);
template Grid<float, 3> solidOccupancy<3>(const std::vector<ObstacleSpec>&, const IVec<3>&, double);
template Grid<uint8_t, 2> solidMask<2>(const std::vector<ObstacleSpec>&, const IVec<2>&, double);
template Grid<uint8_t, 3> solidMask<3>(const std::vector<ObstacleSpec>&, const IVec<3>&, double);

}  // namespace morphoflow
