// Plain settings of the stable-fluids solver (filled by scenes/, owned here).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "fluid/domain_boundary.h"
#include "fluid/obstacle.h"
#include "fluid/smoke_settings.h"

namespace morphoflow {

enum class AdvectionScheme { SemiLagrangian, MacCormack, Bfecc };
enum class PressureSolver { MGPCG, ICPCG, Multigrid };

struct FluidSettings {
  std::vector<int> resolution{128, 128};   // cells per axis (2 or 3 entries)
  std::vector<double> size{1.0, 1.0};      // world size per axis; cells must be cubes
  double density = 1.0;
  double viscosity = 1e-2;                 // kinematic
  AdvectionScheme advection = AdvectionScheme::MacCormack;
  PressureSolver pressureSolver = PressureSolver::MGPCG;
  double pressureTolerance = 1e-6;         // relative residual
  int pressureMaxIterations = 500;
  double viscosityTolerance = 1e-6;        // relative residual of the whole velocity system
  std::array<double, 3> force{0.0, 0.0, 0.0};     // constant body acceleration
  std::array<double, 3> buoyancyDirection{0.0, 1.0, 0.0};
  double buoyancy = 0.0;                   // acceleration per unit dye along buoyancyDirection
  DomainBoundaries boundaries;
  int inflowDyeStripes = 0;                // > 0: dye enters through the inflow in this many stripes
  std::vector<ObstacleSpec> obstacles;
  SmokeSettings smoke;                     // sources, temperature, buoyancy, confinement (fluid/smoke.h)
};

}  // namespace morphoflow
