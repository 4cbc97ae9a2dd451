// Inhomogeneous anisotropic diffusion tensors (seed 004 sec. 3.4).
//
// At each cell a principal direction a (unit vector) and principal
// diffusivities lambda1 (along a) and lambda2 (across it) give
//   sigma = R^T Lambda R = lambda2 I + (lambda1 - lambda2) a a^T     (eq. 12-15)
// which in 2D with a = (cos theta, sin theta) is eq. 15 exactly. A species of
// diffusion rate d then diffuses by div(d sigma grad u) (eq. 11, 17).
//
// Shape (eq. 18-19): with a scale I != 0 the principal diffusivities follow
// the gradient of one species u,
//   dlambda = I (grad u / |grad u|) . a,   Lambda = diag(lambda1 + dlambda, lambda2 - dlambda),
// so spots stretch where the gradient runs along a and shrink where it runs
// against it (tear drops, seed 004 fig. 9). The tensor is then rebuilt every step.
#pragma once

#include <array>
#include <vector>

#include "core/anisotropic_system.h"
#include "core/grid.h"

namespace morphoflow {

template <int D>
struct DiffusionTensorSpec {
  std::array<std::vector<double>, D> direction;  // principal direction per cell (normalised here; 0 = isotropic)
  std::vector<double> lambda1, lambda2;          // principal diffusivities per cell (> 0)
  double shape = 0.0;                            // eq. 18's I; 0 = off
  int shapeSpecies = 0;                          // the species whose gradient shapes the tensor
  std::vector<int> species;                      // the species that diffuse anisotropically (empty: all)

  bool dynamic() const { return shape != 0.0; }
};

// Smallest principal diffusivity the shape term may leave (as a fraction of
// the cell's mean diffusivity): keeps sigma positive definite.
constexpr double kMinPrincipalFraction = 0.05;

// The tensor components per cell, in AnisotropicSystem's order (xx, yy, (zz,)
// xy, (xz, yz)). `shaped` is the shape species (ignored when the spec is not
// dynamic); its gradient uses central differences, wrapped on periodic axes and
// one-sided at walls. Where the direction is zero the tensor is isotropic with
// the mean diffusivity (lambda1 + (D - 1) lambda2) / D.
template <int D>
std::array<std::vector<double>, AnisotropicSystem<D>::kComponents> diffusionTensor(
    const DiffusionTensorSpec<D>& spec, const IVec<D>& cells, bool periodic, const Grid<double, D>* shaped);

}  // namespace morphoflow
