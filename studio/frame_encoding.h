// What the studio sends of a field: a frame (the field as 8-bit values with
// its palette, for the page to draw; 3D fields box-averaged down to a volume
// the page ray-marches), and the field's exact values as a .npy file.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/grid.h"
#include "render/colormap.h"

namespace morphoflow {

// The largest volume side a 3D frame holds (64^3 bytes: 256 KiB).
constexpr int kFrameVolumeSide = 64;

// A binary frame: "MFF1", the length of a JSON header (uint32, little
// endian), the header (`meta` with "dims" and "range" added), 256 RGB
// palette entries, then one byte a cell, x fastest. The values map
// linearly from [lo, hi] (the given range, or the field's own when
// autoRange; centred on 0 when symmetric) to 0..255. A field of several
// grids (the velocity) is shown by its magnitude.
template <int D>
std::string encodeFrame(const std::vector<Grid<float, D>>& field, const Palette& palette, bool autoRange,
                        const double range[2], bool symmetric, nlohmann::json meta);

// The grids as a NumPy .npy file of float32, indexed as the Python module's
// field(): the axes reversed ([y, x], [z, y, x]), the component first when there are several.
template <int D>
std::string npyFile(const std::vector<Grid<float, D>>& field);

}  // namespace morphoflow
