// A 3D field seen whole, inside and out: emission-absorption ray marching
// through the palette (each sample emits its palette colour and absorbs in
// proportion to its value in the range), from the previews' fixed camera
// (render/volume_camera.h), the box's edges drawn faintly: the view of a
// field that fills its box. A smoke element is rendered lit instead
// (render/lit_volume.h). Pixels are independent, so the image does not
// depend on the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "core/grid.h"
#include "render/field_image.h"

namespace morphoflow {

// A `size` x `size` RGB image (top row first).
std::vector<uint8_t> volumeToRgb(const Grid<float, 3>& field, const FieldImageOptions& options, int size, int* width,
                                 int* height);

// Seed 002's two species at once: `red` and `green` give the colour, the
// brighter of the two the opacity.
std::vector<uint8_t> volumeTwoToRgb(const Grid<float, 3>& red, const Grid<float, 3>& green,
                                    const FieldImageOptions& options, int size, int* width, int* height);

}  // namespace morphoflow
