// The colour of a black body at a temperature, as renderers' blackbody
// emission shows it: Planck's law integrated against the CIE 1931 colour
// matching functions (Wyman, Sloan & Shirley 2013's multi-lobe fit), taken
// to linear sRGB (D65) and scaled to luminance 1 (the brightness is the
// emission's strength, as in Blender's Principled Volume).
#pragma once

#include <array>

namespace morphoflow {

// Linear sRGB of luminance 1 at `kelvin` (negative components clipped to 0).
std::array<double, 3> blackbodyColour(double kelvin);

}  // namespace morphoflow
