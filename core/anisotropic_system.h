// AnisotropicSystem<D>: the symmetric system of a tensor diffusion operator
// -h^2 div(sigma grad), seed 004 eq. 11 and 17, written once for 2D and 3D:
//
//   (A x)_p = axis part (a LaplaceSystem: c and the face weights w)
//           + scale * sum_{diagonal pairs (p, q)} K_pq (x_p - x_q)
//
// The axis part carries sigma_aa at the faces (the mean of the two cells, as
// in seed 001 eq. 17). The mixed derivatives d_a(sigma_ab d_b) + d_b(sigma_ab
// d_a) use the standard second-order central discretisation, which couples a
// cell to its diagonal neighbours in the (a, b) plane only:
//
//   K(p, p + e_a + e_b) = +(sigma_ab(p + e_a) + sigma_ab(p + e_b)) / 4
//   K(p, p + e_a - e_b) = -(sigma_ab(p + e_a) + sigma_ab(p - e_b)) / 4
//
// (the two other cells of the 2x2 block). Written as pair couplings the
// operator is symmetric, conserves mass (every row sums to the c term) and
// keeps the tensor gradients (the "inhomogeneous" terms Witkin & Kass drop).
// Pairs that would cross a non-periodic wall are cut (zero flux). For a
// constant positive definite tensor the symbol is
// 4 (s_xx sin^2(kx/2) + s_yy sin^2(ky/2)) + 2 s_xy sin kx sin ky >= 0, so the
// operator is positive semidefinite.
#pragma once

#include <array>

#include "core/laplace_system.h"

namespace morphoflow {

template <int D>
struct AnisotropicSystem {
  static constexpr int kPlanes = D == 2 ? 1 : 3;          // xy (, xz, yz)
  static constexpr int kComponents = D + kPlanes;          // xx, yy, (zz,) xy, (xz, yz)
  // Axes (a, b) of plane p: (0, 1), (0, 2), (1, 2).
  static constexpr int planeAxis(int p, int which) {
    return p == 0 ? which : p == 1 ? 2 * which : 1 + which;
  }

  LaplaceSystem<D> axis;
  bool hasCross = false;                       // false: a plain LaplaceSystem
  std::array<Grid<float, D>, kPlanes> up;      // K(p, p + e_a + e_b)
  std::array<Grid<float, D>, kPlanes> down;    // K(p, p + e_a - e_b)

  AnisotropicSystem() = default;
  // The isotropic system: A = axis.
  explicit AnisotropicSystem(LaplaceSystem<D> isotropic) : axis(std::move(isotropic)) {}

  // -h^2 div(sigma grad) with Neumann (cut) or periodic walls; sigma[k][i] is
  // component k (order of kComponents) of the tensor at cell i. scale = 1/h^2.
  // A tensor without mixed components anywhere gives hasCross = false.
  static AnisotropicSystem fromTensor(const IVec<D>& dims, const std::array<bool, D>& periodic,
                                      double scale, const std::array<const double*, kComponents>& sigma);

  size_t size() const { return axis.size(); }
  bool singular() const { return axis.singular(); }
  void removeNullSpace(Vector* x) const { axis.removeNullSpace(x); }
  void apply(const Vector& x, Vector* y) const;
  // r = b - A x; returns ||r||_2.
  double residual(const Vector& b, const Vector& x, Vector* r) const;
  // c + s * (everything else): the implicit system I - s lap from -h^2 lap
  // (c' = 1 + s c, every coupling times s; scale becomes 1).
  AnisotropicSystem shifted(double s) const;
  // max_p sum_q |A_pq| / scale: a Gershgorin bound on the spectrum.
  double maxRowAbsSum() const;
};

}  // namespace morphoflow
