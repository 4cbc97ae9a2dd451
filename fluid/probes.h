// Measurements a scene can record: centreline velocity profiles (cavity
// validation against Ghia et al. 1982), the force on obstacles (drag and
// lift), the Strouhal number of a lift signal, speed and vorticity fields.
#pragma once

#include <array>
#include <vector>

#include "fluid/fluid_solver.h"

namespace morphoflow {

struct Profile {
  std::vector<double> coord;  // position along the line / domain extent, in [0, 1]
  std::vector<double> value;  // velocity component / reference speed
};

// Component `component` of the velocity along the line parallel to `along`
// through the domain centre, at every cell centre plus both ends.
template <int D>
Profile centerlineProfile(const FluidSolver<D>& fluid, int component, int along, double referenceSpeed);

// Force the fluid exerts on the obstacles: on a staircase (voxel) obstacle's
// cells, pressure on each exposed face plus viscous shear from the adjacent
// tangential velocity (no-slip wall half a cell away); on a cut obstacle,
// the traction integrated on its surface (fluid/surface_forces.h). Returns
// the D components (3rd is 0 in 2D).
template <int D>
std::array<double, 3> obstacleForce(const FluidSolver<D>& fluid);

struct StrouhalEstimate {
  double strouhal = 0.0;       // f L / U
  double frequency = 0.0;
  int periods = 0;             // full periods measured
  double periodSpread = 0.0;   // (max - min) / mean of the measured periods
  std::vector<double> periodStrouhal;  // St of each successive period
};

// Frequency of a periodic signal from its upward mean crossings, using the
// samples with time >= tStart.
StrouhalEstimate estimateStrouhal(const std::vector<double>& time, const std::vector<double>& signal,
                                  double tStart, double length, double speed);

// The signal's mean over the window of the given time centred on each
// sample. A moving body's force flickers at the rate it crosses cells (its
// cut fractions change step by step); a window of the time it takes to
// cross one cell (h / speed) leaves the flow's own frequencies.
std::vector<double> windowMean(const std::vector<double>& time, const std::vector<double>& signal, double window);

// Cell-centred speed |u| and vorticity (2D: the scalar curl; 3D: |curl u|).
template <int D>
Grid<float, D> speedField(const FluidSolver<D>& fluid);
template <int D>
Grid<float, D> vorticityField(const FluidSolver<D>& fluid);

}  // namespace morphoflow
