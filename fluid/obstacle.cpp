#include "fluid/obstacle.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "fluid/obstacle_shape.h"

namespace morphoflow {

double obstacleDistance(const ObstacleSpec& o, const double* x, int dims, const double* size) {
  switch (o.shape) {
    case ObstacleShape::Image:
    case ObstacleShape::Sdf:
      return obstacle_shape::osFieldDistance(o.field.data(), int(o.shape), o.fieldWidth, o.fieldHeight, o.threshold,
                                             o.invert, x, size);
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
