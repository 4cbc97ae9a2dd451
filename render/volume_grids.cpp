// The grids' helpers of render/vdb_volume.h that need no OpenVDB.
#include <cmath>

#include "render/vdb_volume.h"

namespace morphoflow {

VolumeOptions::ActiveMask activeWhere(const VolumeGrid& mask) {
  VolumeOptions::ActiveMask m;
  m.cells = mask.cells;
  const std::vector<float>& v = mask.values.front();
  m.on.resize(v.size());
  for (size_t i = 0; i < v.size(); ++i) m.on[i] = v[i] != 0.0f ? 1 : 0;
  return m;
}

std::map<std::string, uintmax_t> clampToHalf(std::vector<VolumeGrid>* grids) {
  constexpr float kHalfMax = 65504.0f;
  std::map<std::string, uintmax_t> clamped;
  for (VolumeGrid& g : *grids) {
    if (g.kind == VolumeGrid::Kind::LevelSet) continue;
    uintmax_t n = 0;
    for (std::vector<float>& c : g.values)
      for (float& v : c)
        if (std::abs(v) > kHalfMax) v = std::copysign(kHalfMax, v), ++n;
    if (n > 0) clamped[g.name] += n;
  }
  return clamped;
}

}  // namespace morphoflow
