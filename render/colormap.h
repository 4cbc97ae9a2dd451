// Named colormaps: a scalar in [0, 1] to 8-bit RGB. Perceptual maps from
// matplotlib (viridis, magma, inferno; control points every 1/8) and
// Moreland's diverging coolwarm, linearly interpolated.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace morphoflow {

std::vector<std::string> colormapNames();
bool hasColormap(const std::string& name);
// t is clamped to [0, 1].
std::array<uint8_t, 3> colormap(const std::string& name, double t);

}  // namespace morphoflow
