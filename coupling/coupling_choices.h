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
// the cubic B-spline of prefiltered coefficients (coupling/bspline.h), or
// BFECC: linear samples with back and forth error compensation (Dupont &
// Liu 2003; Kim et al. 2005), limited to the foot's linear neighbours.
enum class ChemicalInterpolation { Linear, Cubic, BSpline, BFECC };

inline const char* couplingModeName(CouplingMode m) {
  return m == CouplingMode::Passive ? "passive" : m == CouplingMode::RDOnly ? "rd-only" : "ard";
}
inline const char* interpolationName(ChemicalInterpolation i) {
  switch (i) {
    case ChemicalInterpolation::Cubic: return "cubic";
    case ChemicalInterpolation::BSpline: return "bspline";
    case ChemicalInterpolation::BFECC: return "bfecc";
    default: return "linear";
  }
}

// The names the scene reader accepts (it refuses any other, with its location).
inline CouplingMode couplingModeNamed(const std::string& name) {
  for (CouplingMode m : {CouplingMode::ARD, CouplingMode::Passive, CouplingMode::RDOnly})
    if (name == couplingModeName(m)) return m;
  throw std::invalid_argument("no coupling mode '" + name + "'");
}
inline ChemicalInterpolation interpolationNamed(const std::string& name) {
  for (ChemicalInterpolation i : {ChemicalInterpolation::Linear, ChemicalInterpolation::Cubic,
                                  ChemicalInterpolation::BSpline, ChemicalInterpolation::BFECC})
    if (name == interpolationName(i)) return i;
  throw std::invalid_argument("no interpolation '" + name + "'");
}

}  // namespace morphoflow
