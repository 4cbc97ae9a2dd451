// Cut cells: what the fluid sees of the obstacles whose boundary is "cut".
// The pressure projection weighs each velocity face by its open (fluid)
// fraction, from the obstacles' signed distance (Batty, Bertails & Bridson
// 2007, "A fast variational framework for accurate solid-fluid coupling",
// eq. 8-9: the fraction of the face's area outside the solid); the
// viscosity places its no-slip condition at the surface, a fraction theta
// of the way to the neighbouring face (Gibou, Fedkiw, Cheng & Kang 2002:
// the coupling 1 / theta to the wall's velocity, which keeps the system
// symmetric and the solution second order).
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "core/grid.h"
#include "fluid/obstacle.h"
#include "fluid/obstacle_motion.h"

namespace morphoflow {

// The signed distance of the union of the cut obstacles (negative inside),
// at a world position; +infinity where there are none.
class CutSurface {
 public:
  CutSurface() = default;
  // The cut obstacles (every obstacle with `everyBoundary`), moving as
  // `motions` says (index by index; empty: all at rest).
  CutSurface(const std::vector<ObstacleSpec>& obstacles, int dims, const double* domainSize,
             const std::vector<RigidMotion>& motions = {}, bool everyBoundary = false);
  bool empty() const { return obstacles_.empty(); }
  double distance(const double* x) const;
  // Whether any of its obstacles moves.
  bool moving() const { return !motions_.empty(); }
  // The velocity of the solid nearest x (0 when none moves).
  std::array<double, 3> velocity(const double* x) const;
  // Its component along axis a alone.
  double velocity(const double* x, int a) const;
  // Whether distance() is one (an image shape only has a sign: -1 inside, 1 outside).
  bool exact() const { return exact_; }
  // Whether it changes by at most the distance moved (circles, spheres and
  // boxes: exact distances, a union's least; not a sampled field).
  bool lipschitz() const { return lipschitz_; }
  static constexpr double kMinTheta = 0.01;

 private:
  std::vector<ObstacleSpec> obstacles_;
  std::vector<RigidMotion> motions_;  // empty unless one moves
  bool exact_ = true;
  bool lipschitz_ = true;
  int dims_ = 2;
  double size_[3] = {0, 0, 0};
};

// Gibou et al.'s theta between a point at distance `from` (>= 0, in the
// fluid) and its neighbour at distance `to` (< 0, inside): the distances'
// linear interpolation, at least CutSurface::kMinTheta.
inline double cutTheta(double from, double to) {
  if (!(from > 0.0)) return CutSurface::kMinTheta;
  if (!(to < 0.0)) return 1.0;
  const double t = from / (from - to);
  return t > CutSurface::kMinTheta ? t : CutSurface::kMinTheta;
}

// The open fraction of face k of grid `axis` (a cell face of size h; face k
// lies at x_axis = k h), in [0, 1]: the part where the distance is positive
// (a face on the surface is closed), given the distance at its centre
// (faceCentreDistance). From the distances at its corners (2D: the
// segment's fluid part, linearly interpolated; 3D: the bilinear interpolant
// of 4 x 4 sub-squares' corners, sampled 4 x 4 each); with only a sign (an
// image), by bisection for the crossing (2D) or 8 x 8 samples (3D). Farther
// than faceReach from an exact surface the face lies wholly on one side.
template <int D>
double faceCentreDistance(const CutSurface& surface, int axis, const IVec<D>& k, double h);
template <int D>
float openFractionFrom(const CutSurface& surface, int axis, const IVec<D>& k, double h, double centre);
double faceReach(int dims, double h);

}  // namespace morphoflow
