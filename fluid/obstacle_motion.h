// Obstacles that move: obstacles.N.motion puts the centre, obstacles.N.rotation
// turns the body (2D: an angle about z; 3D: angles about x, y and z, the
// rotation R = Rz Ry Rx), both as expressions in t. The solid's velocity at a
// point is the centre's velocity plus omega x r (r from the centre), with
// omega = az' e_z + ay' Rz e_y + ax' Rz Ry e_x, the derivatives taken
// analytically where the expressions are differentiable (core/expression.h).
#pragma once

#include <array>
#include <vector>

#include "fluid/obstacle.h"

namespace morphoflow {

// A rigid body's velocity field.
struct RigidMotion {
  std::array<double, 3> center{0, 0, 0};
  std::array<double, 3> velocity{0, 0, 0};
  std::array<double, 3> omega{0, 0, 0};  // 2D: only omega_z
  // The velocity at world point x: v + omega x (x - centre).
  std::array<double, 3> at(const double* x, int dims) const;
  double at(const double* x, int dims, int axis) const;  // its component along axis
};

// Whether the obstacle has a motion or a rotation.
inline bool movesAtAll(const ObstacleSpec& o) { return !o.motion.empty() || !o.rotation.empty(); }
bool anyMoves(const std::vector<ObstacleSpec>& obstacles);

// The obstacle where its motion and rotation put it at time t (centre and
// orientation set), and its velocity field then. *analytic (if given) is
// cleared when a derivative had to be taken by a centred difference.
ObstacleSpec placedAt(const ObstacleSpec& o, int dims, double t, RigidMotion* motion, bool* analytic = nullptr);

// Every obstacle placed at t, with their motions (index by index).
std::vector<ObstacleSpec> placedAt(const std::vector<ObstacleSpec>& obstacles, int dims, double t,
                                   std::vector<RigidMotion>* motions);

// The box [lo, hi] (world units) that holds the obstacle, its centre
// wrapped into the domain on the axes it wraps across; false when it has
// none (an image, an sdf, a circle's cylinder in 3D).
bool obstacleBounds(const ObstacleSpec& o, int dims, const double* domainSize, double* lo, double* hi);

// The largest speed of any point of the obstacle at t: |v| + |omega| times
// its farthest point from the centre (0 for an image or sdf shape, which does not move).
double obstacleSpeedBound(const ObstacleSpec& o, int dims, double t);

}  // namespace morphoflow
