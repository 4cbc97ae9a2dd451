#include "gpu/fluid/gpu_obstacles.h"

#include <algorithm>

#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

namespace {
// One obstacle as shaders/cut_geometry.comp reads it (its B_* offsets);
// fieldAt: an image's or sdf's first texel in the fields buffer.
constexpr size_t kStride = 40;
void putBody(const ObstacleSpec& o, const RigidMotion& m, size_t fieldAt, double* r) {
  r[0] = double(int(o.shape));
  r[1] = o.boundary == ObstacleBoundary::Voxel ? 1.0 : 0.0;
  for (size_t a = 0; a < 3; ++a) {
    r[2 + a] = o.center[a];
    r[6 + a] = o.halfSize[a];
    r[18 + a] = o.wrap[a] ? 1.0 : 0.0;
    r[21 + a] = m.center[a];
    r[24 + a] = m.velocity[a];
    r[27 + a] = m.omega[a];
  }
  r[5] = o.radius;
  std::copy(o.orientation.begin(), o.orientation.end(), r + 9);
  r[30] = double(fieldAt);
  r[31] = o.fieldWidth;
  r[32] = o.fieldHeight;
  r[33] = o.threshold;
  r[34] = o.invert ? 1.0 : 0.0;
}
}  // namespace

template <int D>
GpuObstacles<D>::GpuObstacles(const FluidSettings& s, GpuMacGrid<D>* grid)
    : grid_(*grid), boundaries_(s.boundaries), count_(int(s.obstacles.size())) {
  std::vector<float> fields(1, 0.0f);  // the images' and sdfs' fields (they do not move: uploaded once)
  for (const ObstacleSpec& o : s.obstacles) {
    cutCount_ += o.boundary == ObstacleBoundary::Cut ? 1 : 0;
    exact_ = exact_ && !(o.boundary == ObstacleBoundary::Cut && o.shape == ObstacleShape::Image);
    fieldAt_.push_back(fields.size());
    fields.insert(fields.end(), o.field.begin(), o.field.end());
  }
  fields_ = GpuBuffer::of(fields);
  bodies_ = GpuBuffer(std::max<size_t>(1, s.obstacles.size()) * kStride * sizeof(double));
  voxel_ = GpuBuffer(grid_.cellCount * sizeof(uint32_t));
  voxel_.zero();
}

template <int D>
void GpuObstacles<D>::run(const char* mode, int axis, const std::array<int, 3>& lo, const std::array<int, 3>& box) {
  const size_t n = size_t(box[0]) * size_t(box[1]) * size_t(box[2]);
  if (n == 0) return;
  const ComputeProgram& p = useProgram("cut_geometry.comp", fmt::format("#define DIM {}\n#define {}", D, mode));
  std::array<int, 3> lowKind{}, highKind{};
  for (int a = 0; a < D; ++a)
    for (bool high : {false, true}) {
      const BoundaryKind k = boundaries_.side(a, high).kind;
      (high ? highKind : lowKind)[size_t(a)] = k == BoundaryKind::Wall ? 1 : k == BoundaryKind::Inflow ? 2 : 0;
    }
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = grid_.cells[size_t(a)] * grid_.h;
  setUniform(p, "cells", grid_.cells);
  setUniform(p, "lo", lo);
  setUniform(p, "box", box);
  setUniform(p, "periodic", grid_.periodic);
  setUniform(p, "velOff", grid_.velocityOffsets());
  setUniform(p, "lowKind", lowKind);
  setUniform(p, "highKind", highKind);
  setUniform(p, "axis", axis);
  setUniform(p, "n", int(n));
  setUniform(p, "bodies", count_);
  setUniform(p, "cutBodies", cutCount_);
  setUniform(p, "parabolic", boundaries_.profile == InflowProfile::Parabolic ? 1 : 0);
  setUniform(p, "openPerFace", grid_.cut ? 1 : 0);
  setUniform(p, "exactSurface", exact_ ? 1 : 0);
  setUniform(p, "h", grid_.h);
  setUniform(p, "inflowMean", boundaries_.inflowMeanVelocity);
  setUniformDoubles(p, "domainSize", size, 3);
  bodies_.bind(0);
  grid_.solid.bind(1);
  voxel_.bind(2);
  grid_.fixed.bind(3);
  grid_.value.bind(4);
  grid_.open.bind(5);
  if (grid_.solidFlux.bytes()) grid_.solidFlux.bind(6);
  fields_.bind(7);
  dispatchFlat(n, 16.0);
  storageBarrier();
}

template <int D>
void GpuObstacles<D>::place(const std::vector<ObstacleSpec>& placed, const std::vector<RigidMotion>& motions,
                            const IVec<D>& lo, const IVec<D>& hi) {
  std::vector<double> table(std::max<size_t>(1, placed.size()) * kStride, 0.0);
  for (size_t i = 0; i < placed.size(); ++i) putBody(placed[i], motions[i], fieldAt_[i], table.data() + i * kStride);
  bodies_.upload(table);
  std::array<int, 3> l{0, 0, 0}, box{1, 1, 1};
  for (int a = 0; a < D; ++a) l[size_t(a)] = lo[a], box[size_t(a)] = hi[a] - lo[a];
  run("MODE_CELLS", 0, l, box);
  for (int a = 0; a < D; ++a) {
    std::array<int, 3> faces = box;
    faces[size_t(a)] += 1;
    run("MODE_FACES", a, l, faces);
  }
  if (grid_.solidFlux.bytes()) run("MODE_FLUX", 0, l, box);
}

template class GpuObstacles<2>;
template class GpuObstacles<3>;

}  // namespace morphoflow
