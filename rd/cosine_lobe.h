// Kim & Lin's cosine-lobe anisotropy (seed 001 sec. 4, eq. 14-17).
//
// A species A diffuses by div(d a(theta) grad A) (eq. 14), where theta is the
// angle of the x-y projection of the height-field normal [A_x, A_y, -1], i.e.
// theta = atan2(A_y, A_x), and a(theta) is a polar function of
// phi = theta + theta0:
//
//   cosine lobes (eq. 16): j lobes, lobe n (n = 1..j) centred at 2 pi (n-1)/j
//   and limited to the 2 pi / j slice around it,
//     a(phi) = a_n (1 + cos(j phi)) / 2,
//   so a = a_n at the centre and 0 at the slice's edges. (The paper prints the
//   slice as (n-2) pi/j < phi <= n pi/j, which overlaps its neighbours and
//   does not cover the circle; centring the slice on the lobe's maximum is the
//   reading that matches "each lobe limited to a 2 pi / j slice".)
//
//   Witkin-Kass (eq. 15): with alpha = (a1 + a2) / 4,
//     a(phi) = alpha + (a1 - alpha)/2 (1 + cos 4 phi)  for |phi| <= pi/4 (mod pi),
//              alpha + (a2 - alpha)/2 (1 + cos 4 phi)  otherwise,
//   a1 along x, a2 along y, alpha on the diagonals.
//
// The face between two cells diffuses at the mean of their a (eq. 17), which
// keeps the implicit system symmetric; theta comes from the state at the
// step's start (lagged), so each step's system is linear. Where the gradient
// vanishes theta is undefined (the paper notes that diffusion vanishes there
// too): such cells take a's mean over the circle, so a flat region diffuses
// isotropically into its neighbours. In 3D theta is the angle of the gradient's
// x-y projection, and the z faces use the same a.
#pragma once

#include <array>
#include <vector>

#include "core/anisotropic_system.h"
#include "core/grid.h"

namespace morphoflow {

struct CosineLobeSpec {
  std::vector<double> speeds;   // a_1..a_j of eq. 16 (>= 0), or a1, a2 of eq. 15 (> 0)
  bool witkinKass = false;      // eq. 15 instead of eq. 16
  std::vector<double> theta0;   // rotation per cell, radians (empty: 0 everywhere)
  std::vector<int> species;     // the species that diffuse by a(theta) (empty: all)
};

// Throws std::invalid_argument when the speeds do not define a valid a(theta).
void validateCosineLobes(const CosineLobeSpec& spec);

// a(phi), phi = theta + theta0 in radians (any value; 2 pi periodic).
double lobeDiffusivity(const CosineLobeSpec& spec, double phi);
// a's mean over the circle (the value where theta is undefined) and its maximum.
double meanLobeDiffusivity(const CosineLobeSpec& spec);
double maxLobeDiffusivity(const CosineLobeSpec& spec);

// The diagonal tensor a(theta) I per cell from the gradient of u (central
// differences, wrapped if periodic, one-sided at walls), in AnisotropicSystem's
// component order (cross components zero).
template <int D>
std::array<std::vector<double>, AnisotropicSystem<D>::kComponents> lobeTensor(const CosineLobeSpec& spec,
                                                                            const Grid<double, D>& u, bool periodic);

}  // namespace morphoflow
