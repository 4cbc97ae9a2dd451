#include "fluid/cut_cells.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
    }
  if (!moves) motions_.clear();
  for (int a = 0; a < dims; ++a) size_[a] = domainSize[a];
}

std::array<double, 3> CutSurface::velocity(const double* x) const {
  if (motions_.empty()) return {0, 0, 0};
  size_t nearest = 0;
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < obstacles_.size(); ++i) {
    const double di = obstacleDistance(obstacles_[i], x, dims_, size_);
    if (di < d) d = di, nearest = i;
  }
  // Where the obstacle wraps, the point's image nearest its centre.
  const ObstacleSpec& o = obstacles_[nearest];
  double image[3] = {x[0], x[1], dims_ == 3 ? x[2] : 0.0};
  for (int a = 0; a < dims_; ++a)
    if (o.wrap[size_t(a)]) image[a] -= size_[a] * std::round((x[a] - o.center[size_t(a)]) / size_[a]);
  return motions_[nearest].at(image, dims_);
}

double CutSurface::distance(const double* x) const {
  double d = std::numeric_limits<double>::infinity();
  for (const ObstacleSpec& o : obstacles_) d = std::min(d, obstacleDistance(o, x, dims_, size_));
  return d;
}

namespace {

// The fluid part (distance > 0: a face on the surface is closed) of the
// segment whose ends have distances a and b.
double segmentOpen(double a, double b) {
  if (a > 0.0 && b > 0.0) return 1.0;
  if (a <= 0.0 && b <= 0.0) return 0.0;
  return std::max(a, b) / std::abs(a - b);
}

}  // namespace

template <int D>
float openFraction(const CutSurface& surface, int axis, const IVec<D>& k, double h) {
  double c[3] = {0, 0, 0};  // the face's centre
  for (int b = 0; b < D; ++b) c[b] = (k[b] + (b == axis ? 0.0 : 0.5)) * h;
  int t[2] = {0, 0}, m = 0;  // the face's two tangent axes
  for (int b = 0; b < D; ++b)
    if (b != axis) t[m++] = b;
  auto at = [&](double s, double r) {  // distance at face-local (s, r) in [0, 1]^2
    double x[3] = {c[0], c[1], c[2]};
    x[t[0]] += (s - 0.5) * h;
    if (D == 3) x[t[1]] += (r - 0.5) * h;
    return surface.distance(x);
  };
  const double centre = surface.distance(c);
  if (surface.exact()) {
    // Farther than the face's half diagonal from the surface: wholly on one side.
    if (std::abs(centre) > 0.5 * h * std::sqrt(double(D - 1)) + 1e-12 * h) return centre > 0.0 ? 1.0f : 0.0f;
  } else {
    // A sign only: the face is whole where its corners and centre agree.
    bool mixed = false;
    for (int i = 0; i < (D == 2 ? 2 : 4); ++i) mixed = mixed || ((at(i & 1, i >> 1) > 0.0) != (centre > 0.0));
    if (!mixed) return centre > 0.0 ? 1.0f : 0.0f;
  }
  if constexpr (D == 2) {
    const double a = at(0.0, 0.0), b = at(1.0, 0.0);
    if (surface.exact() || (a > 0.0) == (b > 0.0)) return float(segmentOpen(a, b));
    double lo = 0.0, hi = 1.0;  // the crossing, by bisection on the sign
    for (int it = 0; it < 30; ++it) {
      const double mid = 0.5 * (lo + hi);
      ((at(mid, 0.0) > 0.0) == (a > 0.0) ? lo : hi) = mid;
    }
    const double cross = 0.5 * (lo + hi);
    return float(a > 0.0 ? cross : 1.0 - cross);
  }
  int open = 0, total = 0;
  if (!surface.exact()) {  // 8 x 8 samples of the sign
    for (int p = 0; p < 8; ++p)
      for (int q = 0; q < 8; ++q, ++total) open += at((p + 0.5) / 8, (q + 0.5) / 8) > 0.0 ? 1 : 0;
    return float(double(open) / total);
  }
  // 4 x 4 sub-squares, each's bilinear interpolant of its corners sampled 4 x 4.
  constexpr int kSub = 4, kSamples = 4;
  double phi[kSub + 1][kSub + 1];
  for (int i = 0; i <= kSub; ++i)
    for (int j = 0; j <= kSub; ++j) phi[i][j] = at(double(i) / kSub, double(j) / kSub);
  for (int i = 0; i < kSub; ++i)
    for (int j = 0; j < kSub; ++j)
      for (int p = 0; p < kSamples; ++p)
        for (int q = 0; q < kSamples; ++q, ++total) {
          const double u = (p + 0.5) / kSamples, v = (q + 0.5) / kSamples;
          const double value = (1 - u) * (1 - v) * phi[i][j] + u * (1 - v) * phi[i + 1][j] +
                               (1 - u) * v * phi[i][j + 1] + u * v * phi[i + 1][j + 1];
          open += value > 0.0 ? 1 : 0;
        }
  return float(double(open) / total);
}

template float openFraction<2>(const CutSurface&, int, const IVec<2>&, double);
template float openFraction<3>(const CutSurface&, int, const IVec<3>&, double);

}  // namespace morphoflow
