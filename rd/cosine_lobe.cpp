#include "rd/cosine_lobe.h"

#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "rd/grid_difference.h"

namespace morphoflow {

namespace {
constexpr double kTwoPi = 2.0 * M_PI;

// phi wrapped into [0, period).
double wrap(double phi, double period) {
  double w = std::fmod(phi, period);
  if (w < 0) w += period;
  return w >= period ? 0.0 : w;
}
}  // namespace

void validateCosineLobes(const CosineLobeSpec& spec) {
  if (spec.witkinKass) {
    if (spec.speeds.size() != 2)
      throw std::invalid_argument("cosine lobes: Witkin-Kass (eq. 15) takes two speeds, a1 and a2");
    for (double a : spec.speeds)
      if (!(a > 0) || !std::isfinite(a)) throw std::invalid_argument("cosine lobes: Witkin-Kass speeds must be > 0");
    return;
  }
  if (spec.speeds.empty()) throw std::invalid_argument("cosine lobes: at least one lobe speed (eq. 16)");
  for (double a : spec.speeds)
    if (!(a >= 0) || !std::isfinite(a))
      throw std::invalid_argument("cosine lobes: lobe speeds must be >= 0 and finite");
}

double lobeDiffusivity(const CosineLobeSpec& spec, double phi) {
  if (spec.witkinKass) {  // eq. 15
    const double a1 = spec.speeds[0], a2 = spec.speeds[1], alpha = 0.25 * (a1 + a2);
    const double psi = wrap(phi, M_PI);
    const double lobe = 0.5 * (1.0 + std::cos(4.0 * phi));
    const bool alongX = psi <= 0.25 * M_PI || psi >= 0.75 * M_PI;
    return alpha + ((alongX ? a1 : a2) - alpha) * lobe;
  }
  // eq. 16: lobe n - 1 = round(phi / slice) (mod j), centred at its maximum.
  const int j = int(spec.speeds.size());
  const double slice = kTwoPi / j;
  const int n = int(std::floor(wrap(phi, kTwoPi) / slice + 0.5)) % j;
  return spec.speeds[size_t(n)] * 0.5 * (1.0 + std::cos(j * wrap(phi, kTwoPi)));
}

double meanLobeDiffusivity(const CosineLobeSpec& spec) {
  if (spec.witkinKass) return 0.375 * (spec.speeds[0] + spec.speeds[1]);  // 3 alpha / 2
  double sum = 0.0;
  for (double a : spec.speeds) sum += a;
  return 0.5 * sum / double(spec.speeds.size());  // (1 + cos) / 2 averages 1/2 over a slice
}

double maxLobeDiffusivity(const CosineLobeSpec& spec) {
  double m = 0.0;
  for (double a : spec.speeds) m = std::max(m, a);
  return m;  // Witkin-Kass: alpha <= max(a1, a2) / 2
}

template <int D>
std::array<std::vector<double>, AnisotropicSystem<D>::kComponents> lobeTensor(const CosineLobeSpec& spec,
                                                                            const Grid<double, D>& u, bool periodic) {
  std::array<std::vector<double>, AnisotropicSystem<D>::kComponents> sigma;
  for (auto& s : sigma) s.assign(u.size(), 0.0);
  const double mean = meanLobeDiffusivity(spec);
  forEachCell<D>(u.dims(), [&](const IVec<D>& c, size_t i) {
    const double gx = centralDifference<D>(u, c, 0, periodic), gy = centralDifference<D>(u, c, 1, periodic);
    double a = mean;  // theta undefined
    if (gx != 0.0 || gy != 0.0)
      a = lobeDiffusivity(spec, std::atan2(gy, gx) + (spec.theta0.empty() ? 0.0 : spec.theta0[i]));
    for (int k = 0; k < D; ++k) sigma[size_t(k)][i] = a;
  });
  return sigma;
}

template std::array<std::vector<double>, AnisotropicSystem<2>::kComponents> lobeTensor<2>(const CosineLobeSpec&,
                                                                                        const Grid<double, 2>&, bool);
template std::array<std::vector<double>, AnisotropicSystem<3>::kComponents> lobeTensor<3>(const CosineLobeSpec&,
                                                                                        const Grid<double, 3>&, bool);

}  // namespace morphoflow
