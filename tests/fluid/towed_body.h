// Galilean invariance of a moving obstacle: a cylinder (2D) or sphere (3D)
// of diameter 1/10 towed at speed U through still fluid in a channel
// periodic along x, and the same body fixed in a uniform stream -U whose
// walls move with the stream (the towed case's frame; the walls are at
// rest in the fluid's frame, as slip walls would be for the uniform
// stream). The fluid's force on the body is the same in both frames.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "fluid/fluid_solver.h"
#include "fluid/probes.h"

namespace morphoflow::testing {

struct ForceSeries {
  std::vector<double> t, drag, lift;  // coefficients F / (rho U^2 D / 2), per unit span in 2D
};

// cellsPerD: the body's diameter in cells; the channel is `lengthD` D long
// and `widthD` D wide (and deep).
template <int D>
ForceSeries towedBody(bool towed, double reynolds, int cellsPerD, double duration, double lengthD = 40,
                      double widthD = 10, double cfl = 0.5) {
  const double diameter = 0.1, U = 1.0, length = lengthD * diameter, width = widthD * diameter;
  FluidSettings s;
  const int nx = int(std::lround(lengthD * cellsPerD)), ny = int(std::lround(widthD * cellsPerD));
  s.resolution = D == 2 ? std::vector<int>{nx, ny} : std::vector<int>{nx, ny, ny};
  s.size = D == 2 ? std::vector<double>{length, width} : std::vector<double>{length, width, width};
  s.viscosity = U * diameter / reynolds;
  s.boundaries.sides[0].kind = s.boundaries.sides[1].kind = BoundaryKind::Periodic;
  for (int side = 2; side < 2 * D; ++side) s.boundaries.sides[size_t(side)].wallVelocity = {towed ? 0.0 : -U, 0, 0};
  ObstacleSpec body;
  body.shape = D == 2 ? ObstacleShape::Circle : ObstacleShape::Sphere;
  body.radius = 0.5 * diameter;
  // Slightly off the channel's axis, so that the wake's symmetry breaks.
  body.center = {0.5, 0.5 * width + 0.01 * diameter, 0.5 * width};
  if (towed) {
    body.motion = {"0.5 + t", std::to_string(body.center[1])};
    if (D == 3) body.motion.push_back(std::to_string(body.center[2]));
  }
  s.obstacles = {body};
  FluidSolver<D> f(s);
  if (!towed) {
    f.velocity()[0].fill(float(-U));
    f.constraints().apply(&f.velocity());
  }
  ForceSeries out;
  const double area = D == 2 ? diameter : M_PI * diameter * diameter / 4.0;
  const double q = 0.5 * s.density * U * U * area;
  double t = 0.0;
  while (t < duration - 1e-9) {
    // The CFL step counts the body's speed (towed) or the stream's (fixed).
    const double dt = std::min(duration - t, f.cflTimeStep(cfl, cfl * f.h() / U));
    f.step(dt);
    t += dt;
    const std::array<double, 3> F = obstacleForce<D>(f);
    // The towed body's drag opposes +x; the fixed one's stream runs along -x: both along -x.
    out.t.push_back(t);
    out.drag.push_back(-F[0] / q);
    out.lift.push_back(F[1] / q);
  }
  return out;
}

// The mean of v over t in [from, to].
inline double meanOver(const ForceSeries& s, const std::vector<double>& v, double from, double to) {
  double sum = 0.0, w = 0.0;
  for (size_t i = 1; i < s.t.size(); ++i)
    if (s.t[i] >= from && s.t[i] <= to) sum += v[i] * (s.t[i] - s.t[i - 1]), w += s.t[i] - s.t[i - 1];
  return w > 0 ? sum / w : 0.0;
}
// Half the peak-to-peak swing of v over t in [from, to], v first averaged
// over `window` (the time the body crosses a cell: fluid/probes.h).
inline double amplitudeOver(const ForceSeries& s, const std::vector<double>& v, double from, double to, double window) {
  const std::vector<double> m = windowMean(s.t, v, window);
  double lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < s.t.size(); ++i)
    if (s.t[i] >= from && s.t[i] <= to) lo = std::min(lo, m[i]), hi = std::max(hi, m[i]);
  return 0.5 * (hi - lo);
}

}  // namespace morphoflow::testing
