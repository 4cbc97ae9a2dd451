#include "render/blackbody.h"

#include <algorithm>
#include <cmath>

namespace morphoflow {

namespace {

// A lobe of the fit: a Gaussian of width s1 below its centre and s2 above.
double lobe(double x, double mu, double s1, double s2) {
  const double t = (x - mu) / (x < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}

// CIE 1931 2-degree colour matching functions at wavelength nm (Wyman et al. 2013, eq. 2-4).
std::array<double, 3> cie(double nm) {
  return {
      1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) - 0.065 * lobe(nm, 501.1, 20.4, 26.2),
      0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1),
      1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8)};
}

}  // namespace

std::array<double, 3> blackbodyColour(double kelvin) {
  const double T = std::max(kelvin, 100.0);
  double X = 0, Y = 0, Z = 0;
  for (double nm = 380.0; nm <= 780.0; nm += 5.0) {
    // Planck's spectral radiance, up to a constant: lambda^-5 / (exp(c2 / (lambda T)) - 1), c2 in nm K.
    const double l = nm * 1e-3;  // micrometres keep the powers in range
    const double b = 1.0 / (std::pow(l, 5.0) * std::expm1(1.4388e7 / (nm * T)));
    const std::array<double, 3> m = cie(nm);
    X += b * m[0];
    Y += b * m[1];
    Z += b * m[2];
  }
  // XYZ to linear sRGB (IEC 61966-2-1), at luminance 1.
  const std::array<double, 3> rgb{3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
                                  0.0557 * X - 0.2040 * Y + 1.0570 * Z};
  std::array<double, 3> out;
  for (int k = 0; k < 3; ++k) out[size_t(k)] = std::max(0.0, rgb[size_t(k)] / Y);
  return out;
}

}  // namespace morphoflow
