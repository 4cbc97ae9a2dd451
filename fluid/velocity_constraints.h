// Which velocity faces are prescribed (walls, inflow, solid obstacles) and to
// what value; the tangential wall velocities that no-slip ghosts reflect.
// Built once per scene from the domain sides and the solid mask.
#pragma once

#include <array>
#include <vector>

#include "core/mac_velocity.h"
#include "fluid/domain_boundary.h"

namespace morphoflow {

template <int D>
struct VelocityConstraints {
  IVec<D> cells{0};
  double h = 1.0;
  DomainBoundaries boundaries;
  Grid<uint8_t, D> solid;                   // cell flags
  std::array<Grid<uint8_t, D>, D> fixed;    // per face grid: 1 = prescribed
  // The indices of each grid's prescribed faces, ascending, and their
  // values: apply() visits these only, not the whole grid (a cavity
  // prescribes about 1 face in 20 at 128^3, and apply() runs several times
  // a step), and no grid of values is kept.
  std::array<std::vector<size_t>, D> fixedFaces;
  std::array<std::vector<float>, D> fixedValues;

  VelocityConstraints() = default;
  VelocityConstraints(const IVec<D>& cells, double h, const DomainBoundaries& b,
                      const Grid<uint8_t, D>& solid);

  std::array<bool, D> periodic() const;
  // Sets every prescribed face and copies face 0 onto face n on periodic axes.
  void apply(MacVelocity<D>* u) const;
  // The prescribed value of face i of grid a (0 where none is prescribed).
  float prescribed(int a, size_t i) const;
  // All of grid a's prescribed values (0 elsewhere), as one vector.
  std::vector<float> prescribedGrid(int a) const;
  // Inflow normal speed (into the domain) at a position on the inflow side.
  double inflowSpeed(int axis, const Vec<D>& x) const;
};

}  // namespace morphoflow
