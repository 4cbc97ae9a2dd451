// The six (four in 2D) sides of the box domain and what happens there.
#pragma once

#include <array>

namespace morphoflow {

enum class BoundaryKind {
  Wall,      // no-slip, possibly moving tangentially (a cavity lid)
  Inflow,    // prescribed normal velocity (uniform or parabolic), no tangential slip
  Outflow,   // zero-gradient velocity, p = 0 (do-nothing)
  Periodic,  // wraps to the opposite side (both sides must say so)
};

enum class InflowProfile { Uniform, Parabolic };

struct DomainSide {
  BoundaryKind kind = BoundaryKind::Wall;
  std::array<double, 3> wallVelocity{0.0, 0.0, 0.0};  // tangential velocity of a moving wall
};

struct DomainBoundaries {
  // sides[2 a] is the low side of axis a, sides[2 a + 1] the high side.
  std::array<DomainSide, 6> sides{};
  InflowProfile profile = InflowProfile::Parabolic;
  double inflowMeanVelocity = 1.0;  // mean normal speed over the inflow side, into the domain

  const DomainSide& side(int axis, bool high) const { return sides[size_t(2 * axis + (high ? 1 : 0))]; }
  bool periodic(int axis) const { return sides[size_t(2 * axis)].kind == BoundaryKind::Periodic; }
};

}  // namespace morphoflow
