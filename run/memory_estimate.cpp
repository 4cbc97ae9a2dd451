#include "run/memory_estimate.h"

#include <fmt/format.h>

#include "scenes/scene.h"
#include "core/error.h"

namespace morphoflow {

namespace {

// Peak bytes per cell beyond the fixed overhead, measured by `bench memory`
// (2D 1024^2, 3D 128^3, four steps and the final checkpoint;
// docs/performance.md "Memory"): the fluid (velocity, pressure and viscosity
// systems, their warm starts, and the work vectors its stages borrow in
// turn, the advection's destination among them) and each species of a reaction-diffusion layer
// (double state, its implicit system and warm start, a share of the solves'
// vectors; in a coupled run also its advection scratch and feet; float
// state for the fused explicit step).
constexpr double kFluidBytesPerCell[2] = {132.0, 79.0};  // 2D, 3D
// A coupled run's fluid and species, each from two runs (the same grid for
// both, and chemicals twice as fine: 2D 512^2 / 1024^2, 3D the shipped
// 128^3 / 256^3 cavity) solved for the two unknowns (in 3D the fluid's work
// vectors are the finer layer's, borrowed from one pool).
constexpr double kCoupledFluidBytesPerCell[2] = {79.9, 52.4};
constexpr double kSpeciesBytesPerCell[2] = {26.0, 27.3};         // reaction-diffusion only
constexpr double kCoupledSpeciesBytesPerCell[2] = {23.2, 24.4};  // carried by a fluid
constexpr double kFusedSpeciesBytesPerCell = 16.0;               // the fused explicit step
// A frame's OpenVDB volumes: each grid is built densely, then as a tree,
// before the file is written, on top of the solvers' work vectors when the
// frame follows a step (measured on the shipped 3D cavity's frames, whose
// peak they raise by 0.73 GiB: species and density at 256^3, the velocity's
// three components at 128^3; 12-16 bytes a voxel from 64^3 up).
constexpr double kVdbBytesPerVoxel = 13.8;
constexpr double kFixedBytes = 126.0 * (1 << 20);                // the program, its libraries and thread pools

double cellsOf(const std::vector<int>& res) {
  double n = 1;
  for (int r : res) n *= r;
  return n;
}

}  // namespace

uintmax_t estimateRunBytes(const Scene& s) {
  const int d = s.dimension == 3 ? 1 : 0;
  double bytes = kFixedBytes;
  if (s.hasFluid)
    bytes += cellsOf(s.fluid.resolution) * (s.rd.enabled ? kCoupledFluidBytesPerCell[d] : kFluidBytesPerCell[d]);
  const bool smoke = s.hasFluid && s.fluid.smoke.enabled;
  if (smoke)  // counted, not measured: the temperature, each source's cover, and the forces' float work
              // grids (forces, centre velocities, vorticity and its magnitude: 6 in 2D, 10 in 3D)
    bytes += cellsOf(s.fluid.resolution) * 4.0 * (1.0 + double(s.fluid.smoke.sources.size()) + (d ? 10.0 : 6.0));
  if (s.output.vdb) {
    // species and density at the layer's cells (else the fluid's); three
    // velocity components, extra fields (and vel_mac's three, an obstacle) at the fluid's
    const double fluidCells = s.hasFluid ? cellsOf(s.fluid.resolution) : 0.0;
    const double layerCells = s.rd.enabled ? cellsOf(s.rd.settings.resolution) : fluidCells;
    const double species = s.rd.enabled ? double(s.rd.initial.values.size()) : 0.0;
    double voxels = layerCells * (species + 1.0) + fluidCells * (3.0 + double(s.output.vdbFields.size()));
    if (s.output.vdbMacVelocity) voxels += fluidCells * 3.0;
    if (s.hasFluid && !s.fluid.obstacles.empty()) voxels += fluidCells;
    if (smoke) voxels += fluidCells + (s.output.vdbColor ? 3.0 * layerCells : 0.0);  // temperature, color
    bytes += kVdbBytesPerVoxel * voxels;
  }
  if (s.rd.enabled) {
    const double species = double(s.rd.initial.values.size());
    const bool fused = !s.hasFluid && !s.velocity.enabled && s.rd.plainExplicit();
    bytes += cellsOf(s.rd.settings.resolution) * species *
             (s.hasFluid ? kCoupledSpeciesBytesPerCell[d]
              : fused    ? kFusedSpeciesBytesPerCell
                         : kSpeciesBytesPerCell[d]);
  }
  return uintmax_t(bytes);
}

void checkRunFits(const Scene& scene) {
  const uintmax_t need = estimateRunBytes(scene), have = availableBytes();
  if (need > have)
    throw UserError({scene.path, 0, 0}, "grid.resolution",
                    "this run needs about " + humanBytes(need) + " of memory, and " + humanBytes(have) +
                        " are available",
                    "lower grid.resolution or rd.resolution, or run it on a larger machine");
}

}  // namespace morphoflow
