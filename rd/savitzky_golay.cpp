#include "rd/savitzky_golay.h"

#include <cmath>
#include <stdexcept>
#include <algorithm>
#include <vector>

namespace morphoflow {

Kernel5 savitzkyGolayDerivative(int i, int j, int degree) {
  if (degree < 0 || degree > 8 || i < 0 || j < 0 || i > 4 || j > 4 || i + j > degree)
    throw std::invalid_argument("Savitzky-Golay: need i, j <= 4 and i + j <= degree <= 8");
  // The monomials x^p y^q, p + q <= degree (eq. 31-32), each power at most 4:
  // five samples per axis determine no higher power (x^5 is a combination of
  // 1 ... x^4 on {-2, ..., 2}). X (eq. 33) has one row per sample.
  std::vector<std::array<int, 2>> terms;
  for (int t = 0; t <= degree; ++t)
    for (int q = 0; q <= t; ++q)
      if (t - q <= 4 && q <= 4) terms.push_back({t - q, q});
  constexpr size_t kMaxTerms = 25;  // the full tensor product, degree 8
  const size_t m = std::min(terms.size(), kMaxTerms);
  std::array<std::array<double, kMaxTerms>, 25> X{};
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx)
      for (size_t k = 0; k < m; ++k)
        X[size_t((dy + 2) * 5 + dx + 2)][k] = std::pow(double(dx), terms[k][0]) * std::pow(double(dy), terms[k][1]);
  // X^+ = (X^T X)^-1 X^T (eq. 34): solve (X^T X) Z = X^T by Gauss-Jordan with partial pivoting.
  std::array<std::array<double, kMaxTerms + 25>, kMaxTerms> N{};
  for (size_t a = 0; a < m; ++a) {
    for (size_t b = 0; b < m; ++b)
      for (size_t r = 0; r < 25; ++r) N[a][b] += X[r][a] * X[r][b];
    for (size_t r = 0; r < 25; ++r) N[a][m + r] = X[r][a];
  }
  for (size_t c = 0; c < m; ++c) {
    size_t p = c;
    for (size_t r = c + 1; r < m; ++r)
      if (std::abs(N[r][c]) > std::abs(N[p][c])) p = r;
    std::swap(N[c], N[p]);
    const double pivot = N[c][c];
    if (std::abs(pivot) < 1e-12)
      throw std::invalid_argument("Savitzky-Golay: the fit is singular (degree too high for 5 x 5)");
    for (size_t k = 0; k < m + 25; ++k) N[c][k] /= pivot;
    for (size_t r = 0; r < m; ++r) {
      if (r == c || N[r][c] == 0.0) continue;
      const double f = N[r][c];
      for (size_t k = 0; k < m + 25; ++k) N[r][k] -= f * N[c][k];
    }
  }
  size_t row = 0;
  while (terms[row][0] != i || terms[row][1] != j) ++row;
  const double factorial = std::tgamma(i + 1.0) * std::tgamma(j + 1.0);  // eq. 35: i! j! a_ij
  Kernel5 k{};
  for (int r = 0; r < 25; ++r) k[size_t(r / 5)][size_t(r % 5)] = factorial * N[row][m + size_t(r)];
  return k;
}

}  // namespace morphoflow
