// A polar plot as an image (seed 000 fig. 1's propagator plots): r(phi) for
// phi sampled evenly over the circle, scaled so the largest r reaches near
// the edge, drawn over faint axes and the unit-radius circle of the largest
// value. Negative values (a Gram-Charlier expansion's tails) are drawn at 0.
#pragma once

#include <cstdint>
#include <vector>

namespace morphoflow {

// RGB, `size` x `size` pixels, y up (the image's top row is +y).
std::vector<uint8_t> polarPlotRgb(const std::vector<double>& radius, int size);

}  // namespace morphoflow
