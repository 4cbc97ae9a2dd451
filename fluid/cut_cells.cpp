#include "fluid/cut_cells.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fluid/obstacle_shape.h"

namespace morphoflow {

CutSurface::CutSurface(const std::vector<ObstacleSpec>& obstacles, int dims, const double* domainSize,
                       const std::vector<RigidMotion>& motions, bool everyBoundary)
    : dims_(dims) {
  bool moves = false;
  for (size_t i = 0; i < obstacles.size(); ++i)
    if (everyBoundary || obstacles[i].boundary == ObstacleBoundary::Cut) {
      obstacles_.push_back(obstacles[i]);
      motions_.push_back(i < motions.size() ? motions[i] : RigidMotion{});
      moves = moves || (i < motions.size() && movesAtAll(obstacles[i]));
      exact_ = exact_ && obstacles[i].shape != ObstacleShape::Image;
      lipschitz_ = lipschitz_ && obstacles[i].shape != ObstacleShape::Image && obstacles[i].shape != ObstacleShape::Sdf;
    }
  if (!moves) motions_.clear();
  for (int a = 0; a < dims; ++a) size_[a] = domainSize[a];
}

std::array<double, 3> CutSurface::velocity(const double* x) const {
  return {velocity(x, 0), velocity(x, 1), velocity(x, 2)};
}

double CutSurface::velocity(const double* x, int axis) const {
  if (motions_.empty()) return 0.0;
  size_t nearest = 0;
  double d = std::numeric_limits<double>::infinity();
  if (obstacles_.size() > 1)  // (one obstacle is the nearest, at any distance)
    for (size_t i = 0; i < obstacles_.size(); ++i) {
      const double di = obstacleDistance(obstacles_[i], x, dims_, size_);
      if (di < d) d = di, nearest = i;
    }
  // Where the obstacle wraps, the point's image nearest its centre.
  const ObstacleSpec& o = obstacles_[nearest];
  double image[3] = {x[0], x[1], dims_ == 3 ? x[2] : 0.0};
  for (int a = 0; a < dims_; ++a)
    if (o.wrap[size_t(a)]) image[a] -= size_[a] * obstacle_shape::osRound((x[a] - o.center[size_t(a)]) / size_[a]);
  return motions_[nearest].at(image, dims_, axis);
}

double CutSurface::distance(const double* x) const {
  double d = std::numeric_limits<double>::infinity();
  for (const ObstacleSpec& o : obstacles_) d = std::min(d, obstacleDistance(o, x, dims_, size_));
  return d;
}

namespace {
// kernels/cut_fraction.inc, shared with the GPU (kernels/README.md)
#define CF_REAL double
#define CF_FN inline double
#define CF_IN3(name) const double* name
#define CF_SQRT std::sqrt
#define CF_ABS std::abs
#define CF_LIT(v) v
#define CF_PRECISE
#define CF_DISTANCE(x) surface.distance(x)
#define CF_SURFACE_PARAM const CutSurface &surface,
#define CF_SURFACE_ARG surface,
#include "kernels/cut_fraction.inc"
}  // namespace

template <int D>
double faceCentreDistance(const CutSurface& surface, int axis, const IVec<D>& k, double h) {
  return cfFaceCentreDistance(surface, D, axis, k[0], k[1], D == 3 ? k[2] : 0, h);
}

template <int D>
float openFractionFrom(const CutSurface& surface, int axis, const IVec<D>& k, double h, double centre) {
  return float(cfOpenFractionFrom(surface, D, axis, k[0], k[1], D == 3 ? k[2] : 0, h, surface.exact(), centre));
}

double faceReach(int dims, double h) { return cfFaceReach(dims, h); }

template double faceCentreDistance<2>(const CutSurface&, int, const IVec<2>&, double);
template double faceCentreDistance<3>(const CutSurface&, int, const IVec<3>&, double);
template float openFractionFrom<2>(const CutSurface&, int, const IVec<2>&, double, double);
template float openFractionFrom<3>(const CutSurface&, int, const IVec<3>&, double, double);

}  // namespace morphoflow
