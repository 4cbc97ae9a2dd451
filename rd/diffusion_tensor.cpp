#include "rd/diffusion_tensor.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "rd/grid_difference.h"

namespace morphoflow {

template <int D>
std::array<std::vector<double>, AnisotropicSystem<D>::kComponents> diffusionTensor(
    const DiffusionTensorSpec<D>& spec, const IVec<D>& cells, bool periodic, const Grid<double, D>* shaped) {
  constexpr int kC = AnisotropicSystem<D>::kComponents;
  size_t n = 1;
  for (int a = 0; a < D; ++a) n *= size_t(cells[a]);
  std::array<std::vector<double>, kC> sigma;
  for (auto& s : sigma) s.assign(n, 0.0);
  const bool shape = spec.dynamic() && shaped;
  forEachCell<D>(cells, [&](const IVec<D>& c, size_t i) {
    double a[D], len2 = 0.0;
    for (int k = 0; k < D; ++k) {
      a[k] = spec.direction[size_t(k)][i];
      len2 += a[k] * a[k];
    }
    double l1 = spec.lambda1[i], l2 = spec.lambda2[i];
    if (!(len2 > 0.0)) {  // no direction: isotropic with the mean diffusivity
      const double mean = (l1 + (D - 1) * l2) / D;
      for (int k = 0; k < D; ++k) sigma[size_t(k)][i] = mean;
      return;
    }
    const double inv = 1.0 / std::sqrt(len2);
    for (double& v : a) v *= inv;
    if (shape) {  // eq. 18-19
      double g[D], g2 = 0.0;
      for (int k = 0; k < D; ++k) {
        g[k] = centralDifference<D>(*shaped, c, k, periodic);
        g2 += g[k] * g[k];
      }
      if (g2 > 0.0) {
        double dot = 0.0;
        for (int k = 0; k < D; ++k) dot += g[k] * a[k];
        const double dl = spec.shape * dot / std::sqrt(g2);
        const double floor = kMinPrincipalFraction * (l1 + (D - 1) * l2) / D;
        l1 = std::max(l1 + dl, floor);
        l2 = std::max(l2 - dl, floor);
      }
    }
    // sigma = lambda2 I + (lambda1 - lambda2) a a^T   (eq. 15)
    const double dl = l1 - l2;
    for (int k = 0; k < D; ++k) sigma[size_t(k)][i] = l2 + dl * a[k] * a[k];
    for (int p = 0; p < AnisotropicSystem<D>::kPlanes; ++p) {
      const int x = AnisotropicSystem<D>::planeAxis(p, 0), y = AnisotropicSystem<D>::planeAxis(p, 1);
      sigma[size_t(D + p)][i] = dl * a[x] * a[y];
    }
  });
  return sigma;
}

template std::array<std::vector<double>, AnisotropicSystem<2>::kComponents> diffusionTensor<2>(
    const DiffusionTensorSpec<2>&, const IVec<2>&, bool, const Grid<double, 2>*);
template std::array<std::vector<double>, AnisotropicSystem<3>::kComponents> diffusionTensor<3>(
    const DiffusionTensorSpec<3>&, const IVec<3>&, bool, const Grid<double, 3>*);

}  // namespace morphoflow
