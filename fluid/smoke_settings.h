// Plain settings of production smoke (Fedkiw, Stam & Jensen 2001): the smoke
// density rides in the fluid's dye, a temperature field beside it, both
// carried by the fluid's advection; sources emit them (filled by scenes/).
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "fluid/obstacle.h"

namespace morphoflow {

// A region that emits while start <= t < end, per unit time and volume:
// smoke density, temperature, and (inject) a velocity the fluid takes there.
struct SmokeSource {
  ObstacleSpec region;  // the obstacles' shapes (circle, sphere, box, image, sdf)
  double start = 0.0, end = std::numeric_limits<double>::infinity();
  double density = 0.0;      // smoke per unit volume per unit time
  double temperature = 0.0;  // temperature rise per unit time
  bool inject = false;
  std::array<double, 3> velocity{0.0, 0.0, 0.0};
  std::vector<double> chemicals;  // a coupled scene's species set here while it emits (empty: none)
  std::vector<std::string> motion;  // the centre per axis as expressions in t (empty: fixed at region.center)
};

struct SmokeSettings {
  bool enabled = false;
  double weight = 0.0;    // alpha: downward acceleration per unit smoke density
  double heat = 0.0;      // beta: upward acceleration per unit temperature above ambient
  double ambient = 0.0;   // T_ambient (the temperature field starts there)
  double vorticity = 0.0; // epsilon of the vorticity confinement (0: none)
  double dissipation = 0.0;  // smoke density decays as exp(-dissipation t)
  double cooling = 0.0;      // T - T_ambient decays as exp(-cooling t)
  std::vector<SmokeSource> sources;
};

}  // namespace morphoflow
