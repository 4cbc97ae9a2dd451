// Implicit viscosity (Stam 1999): (I - nu dt lap) u = u*, per velocity
// component on its face grid, no-slip at walls through mirrored ghost values
// (moving walls reflect their velocity), zero gradient at outflow. Solved by
// Jacobi-preconditioned CG: the system is diagonally dominant for any dt.
#pragma once

#include "core/solver_result.h"
#include "core/pcg.h"
#include "fluid/velocity_constraints.h"

namespace morphoflow {

template <int D>
class ViscositySolver {
 public:
  ViscositySolver(const VelocityConstraints<D>& constraints, const SolverOptions& options)
      : vc_(constraints), options_(options) {}
  // Diffuses u in place; returns the worst of the component solves.
  SolverResult diffuse(MacVelocity<D>* u, double viscosity, double dt) const;

 private:
  const VelocityConstraints<D>& vc_;
  SolverOptions options_;
};

}  // namespace morphoflow
