// The coupling's choices as the scene states them ([coupling] mode and
// interpolation): parsed once, where the scene is read, into these enums.
#pragma once

#include <stdexcept>
#include <string>

namespace morphoflow {

// ard: Kim & Lin's advection-reaction-diffusion (seed 001 sec. 5); passive:
// the chemicals carried, no reaction or diffusion; rd-only: not carried.
enum class CouplingMode { ARD, Passive, RDOnly };
// The chemicals' back-trace sample: linear (seed 001 eq. 20), Catmull-Rom,
// or the cubic B-spline of prefiltered coefficients (coupling/bspline.h).
enum class ChemicalInterpolation { Linear, Cubic, BSpline };

inline const char* couplingModeName(CouplingMode m) {
  return m == CouplingMode::Passive ? "passive" : m == CouplingMode::RDOnly ? "rd-only" : "ard";
}
inline const char* interpolationName(ChemicalInterpolation i) {
  return i == ChemicalInterpolation::Cubic ? "cubic" : i == ChemicalInterpolation::BSpline ? "bspline" : "linear";
}

// The names the scene reader accepts (it refuses any other, with its location).
inline CouplingMode couplingModeNamed(const std::string& name) {
  for (CouplingMode m : {CouplingMode::ARD, CouplingMode::Passive, CouplingMode::RDOnly})
    if (name == couplingModeName(m)) return m;
  throw std::invalid_argument("no coupling mode '" + name + "'");
}
inline ChemicalInterpolation interpolationNamed(const std::string& name) {
  for (ChemicalInterpolation i : {ChemicalInterpolation::Linear, ChemicalInterpolation::Cubic, ChemicalInterpolation::BSpline})
    if (name == interpolationName(i)) return i;
  throw std::invalid_argument("no interpolation '" + name + "'");
}

}  // namespace morphoflow
