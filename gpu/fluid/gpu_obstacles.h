// Moving obstacles placed on the device: at every step the solid flags, the
// faces' fixed flags, held velocities and open fractions, and the solid's
// flux, of the cells a move touched, computed by shaders/cut_geometry.comp
// into the GpuMacGrid's buffers with the host's formulas
// (kernels/obstacle_shape.inc, cut_fraction.inc), so they are the CPU's to
// the bit. Only the obstacles' placements (a few doubles each) go up;
// nothing comes back. Every shape: an image's or sdf's field (which does
// not move) is uploaded once.
#pragma once

#include <vector>

#include "fluid/fluid_settings.h"
#include "fluid/obstacle_motion.h"
#include "gpu/fluid/gpu_mac_grid.h"
#include "gpu/gpu_buffer.h"

namespace morphoflow {

template <int D>
class GpuObstacles {
 public:
  GpuObstacles(const FluidSettings& settings, GpuMacGrid<D>* grid);
  // The obstacles as `placed`, moving as `motions`, within the cells
  // [lo, hi): the grid's flags, values, fractions and flux there.
  void place(const std::vector<ObstacleSpec>& placed, const std::vector<RigidMotion>& motions, const IVec<D>& lo,
             const IVec<D>& hi);

 private:
  void run(const char* mode, int axis, const std::array<int, 3>& lo, const std::array<int, 3>& box);

  GpuMacGrid<D>& grid_;
  DomainBoundaries boundaries_;
  int count_ = 0, cutCount_ = 0;
  bool exact_ = true;            // no cut image: the cut surface's distance is one (an image's is a sign)
  std::vector<size_t> fieldAt_;  // each obstacle's first texel in fields_
  GpuBuffer bodies_, voxel_, fields_;
};

}  // namespace morphoflow
