// A 3D field rendered as production volume renderers light smoke: single
// scattering of a key light with self-shadowing (a transmittance volume
// toward the light, swept plane by plane), a sky term shadowed from above,
// optional blackbody emission from the temperature, the palette colouring
// the scattering albedo, and an exposure chosen from the data. Multiple
// scattering is approximated by Wrenninge's octaves (2015, "Art-directable
// multiple volumetric scattering"): sum_i a^i exp(-b^i tau), a = 0.3, b = 1/2.
//
// Everything is computed in a fixed order (planes one after another, pixels
// independently, the exposure from sorted values), so a frame is the same
// bytes on any thread count. The camera is the previews' fixed view
// (render/volume_camera.h), over a plain background, as a renderer shows an
// element (no box drawn).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/grid.h"
#include "render/field_image.h"

namespace morphoflow {

struct LitVolume {
  // What scatters and absorbs: the extinction is proportional to it (the
  // scale chosen from the data, LitImage::extinction). Every grid spans the
  // same box; each may have its own resolution.
  const Grid<float, 3>* density = nullptr;
  // The field whose palette colour (options.palette over its range) is the
  // scattering albedo; none: a white albedo.
  const Grid<float, 3>* shown = nullptr;
  FieldImageOptions options;
  // Blackbody emission: kelvin = kKelvinAtAmbient + kKelvinPerUnit (T - ambient),
  // at `emission` times the key light's strength per unit of density; 0: none.
  const Grid<float, 3>* temperature = nullptr;
  double ambientTemperature = 0.0;
  double emission = 0.0;
  // The obstacles (1 inside, 0 in the fluid; none: no obstacle): drawn as
  // an opaque grey surface, lit by the key and the sky, that hides what lies
  // behind it. The exposure is the smoke's alone; the obstacles have their
  // own, fixed, so that they keep their brightness from frame to frame.
  const Grid<float, 3>* solid = nullptr;
};

// The obstacles' grey (linear albedo) and exposure.
inline constexpr double kObstacleAlbedo = 0.3;
inline constexpr double kObstacleExposure = 2.0;

// The temperature (scene units above the ambient) to kelvin, as the Blender
// set-up maps it too (app's `blender` command).
inline constexpr double kKelvinAtAmbient = 800.0;
inline constexpr double kKelvinPerUnit = 250.0;

// The lights (linear sRGB, per unit of strength): a warm key, a blue sky.
inline constexpr std::array<double, 3> kKeyLight{1.0, 0.92, 0.82};
inline constexpr std::array<double, 3> kSkyLight{0.06, 0.078, 0.108};
// The background behind the element (linear; 0.06 once encoded).
inline constexpr std::array<double, 3> kBackdrop{0.0048, 0.0048, 0.0048};

// The direction toward the key light (world axes, y up): from above the
// camera's left, whatever the box.
std::array<double, 3> keyLightDirection();

// The extinction per unit of density per unit length for a density whose
// 90th percentile (of the values above a thousandth of the largest) is q90,
// in a box whose largest side is `side` long: optical depth 1 over a
// hundred-and-twentieth of that side at q90 (crisp, as thick smoke). A cell is a unit of length to the preview;
// Blender's Principled Volume takes it per scene unit as its Density.
double extinctionPerLength(double q90, double side);
// The q90 of a density's values, as extinctionPerLength takes it.
double densityQ90(const float* values, size_t n);

struct LitImage {
  int size = 0;
  std::vector<uint8_t> rgb;    // size x size, top row first, sRGB
  std::vector<float> opacity;  // 1 - the transmittance along each pixel's ray
  double extinction = 0.0;     // per unit of density per cell length
  double exposure = 0.0;       // the scale of the linear radiance before the tone curve
};

LitImage renderLitVolume(const LitVolume& volume, int size);

}  // namespace morphoflow
