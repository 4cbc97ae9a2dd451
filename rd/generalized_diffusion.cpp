#include "rd/generalized_diffusion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"

namespace morphoflow {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// Table 2 of seed 000: columns (a) to (f).
const std::array<std::pair<const char*, KramersMoyalTensors>, 6> kPresets{{
    {"a", {{1, 0, 1}, {0, 0, 0, 0}, {0, 0, 0, 0, 0}}},
    {"b", {{1, 0, 2}, {0, 0, 0, 0}, {0, 0, 0, 0, 0}}},
    {"c", {{1, 0, 1}, {1, -1, -1, 1}, {0, 0, 0, 0, 0}}},
    {"d", {{1, 0, 1}, {0, 0, 0, 0}, {1, 0, -1, 0, 1}}},
    {"e", {{1, 0, 1}, {0, 0, 0, 0}, {-1, 0, 1, 0, -1}}},
    {"f", {{1, 0, 2}, {0, 0, 0, 0}, {-1, 0, 1, 0, -1}}},
}};

// Component of a symmetric rank-n tensor with index list idx (0 = x, 1 = y):
// the unique component with as many y's.
template <size_t N>
double component(const std::array<double, N>& unique, std::initializer_list<int> idx) {
  size_t ys = 0;
  for (int i : idx) ys += size_t(i);
  return unique[ys];
}

// d^(i+j)/dx^i dy^j by central differences (second order only).
Kernel5 centralSecond(int i, int j) {
  Kernel5 k{};
  if (i == 2) k[2][1] = 1, k[2][2] = -2, k[2][3] = 1;
  if (j == 2) k[1][2] = 1, k[2][2] = -2, k[3][2] = 1;
  if (i == 1 && j == 1) k[3][3] = 0.25, k[1][1] = 0.25, k[1][3] = -0.25, k[3][1] = -0.25;
  return k;
}

}  // namespace

std::vector<std::string> kramersMoyalPresets() {
  std::vector<std::string> names;
  for (const auto& [n, t] : kPresets) names.push_back(n);
  return names;
}

const KramersMoyalTensors* kramersMoyalPreset(const std::string& name) {
  for (const auto& [n, t] : kPresets)
    if (name == n) return &t;
  return nullptr;
}

KramersMoyalTensors rotated(const KramersMoyalTensors& t, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double R[2][2] = {{c, -s}, {s, c}};
  KramersMoyalTensors r;
  // D'_{i1..in} = R_{i1 a1} ... R_{in an} D_{a1..an}, evaluated on the unique components.
  for (size_t ys = 0; ys < 3; ++ys) {
    const int i = ys >= 2 ? 1 : 0, j = ys >= 1 ? 1 : 0;
    double v = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) v += R[i][a] * R[j][b] * component(t.d2, {a, b});
    r.d2[ys] = v;
  }
  for (size_t ys = 0; ys < 4; ++ys) {
    const int idx[3] = {ys >= 3 ? 1 : 0, ys >= 2 ? 1 : 0, ys >= 1 ? 1 : 0};
    double v = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int e = 0; e < 2; ++e) v += R[idx[0]][a] * R[idx[1]][b] * R[idx[2]][e] * component(t.d3, {a, b, e});
    r.d3[ys] = v;
  }
  for (size_t ys = 0; ys < 5; ++ys) {
    const int idx[4] = {ys >= 4 ? 1 : 0, ys >= 3 ? 1 : 0, ys >= 2 ? 1 : 0, ys >= 1 ? 1 : 0};
    double v = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int e = 0; e < 2; ++e)
          for (int f = 0; f < 2; ++f)
            v += R[idx[0]][a] * R[idx[1]][b] * R[idx[2]][e] * R[idx[3]][f] * component(t.d4, {a, b, e, f});
    r.d4[ys] = v;
  }
  return r;
}

GeneralizedDiffusion::GeneralizedDiffusion(const KramersMoyalTensors& t, int nx, int ny, double h,
                                           SecondDerivatives second, int degree)
    : nx_(nx), ny_(ny), k_{} {
  if (nx < 5 || ny < 5) throw std::invalid_argument("generalized diffusion: the grid needs at least 5 x 5 cells");
  // eq. 20-21: (order, i, j, weight) with the multiplicities of eq. 16.
  struct Term {
    int i, j;
    double w;
  };
  const Term terms[] = {{2, 0, t.d2[0]},     {1, 1, 2 * t.d2[1]},   {0, 2, t.d2[2]},     {3, 0, t.d3[0]},
                        {2, 1, 3 * t.d3[1]}, {1, 2, 3 * t.d3[2]},   {0, 3, t.d3[3]},     {4, 0, t.d4[0]},
                        {3, 1, 4 * t.d4[1]}, {2, 2, 6 * t.d4[2]},   {1, 3, 4 * t.d4[3]}, {0, 4, t.d4[4]}};
  for (const Term& term : terms) {
    if (term.w == 0.0) continue;
    const bool central = term.i + term.j == 2 && second == SecondDerivatives::CentralDifferences;
    const Kernel5 d = central ? centralSecond(term.i, term.j) : savitzkyGolayDerivative(term.i, term.j, degree);
    const double scale = term.w / std::pow(h, term.i + term.j);
    for (size_t r = 0; r < 5; ++r)
      for (size_t c = 0; c < 5; ++c) k_[r][c] += scale * d[r][c];
  }
  // The frequencies the spectral radius is taken over: the grid's own, or a
  // 512 x 512 sampling of the torus for larger grids.
  const int fx = std::min(nx, 512), fy = std::min(ny, 512);
  symbols_.resize(size_t(fx) * size_t(fy));
  for (int q = 0; q < fy; ++q)
    for (int p = 0; p < fx; ++p)
      symbols_[size_t(q) * size_t(fx) + size_t(p)] = symbol(kTwoPi * p / fx, kTwoPi * q / fy);
}

void GeneralizedDiffusion::apply(const std::vector<double>& x, std::vector<double>* out) const {
  out->resize(x.size());
  std::vector<double>& o = *out;
  parallelFor(size_t(ny_), [&](size_t y) {
    const double* rows[5];
    for (int dy = -2; dy <= 2; ++dy) rows[dy + 2] = x.data() + size_t((int(y) + dy + ny_) % ny_) * size_t(nx_);
    for (int xi = 0; xi < nx_; ++xi) {
      int cols[5];
      for (int dx = -2; dx <= 2; ++dx) cols[dx + 2] = (xi + dx + nx_) % nx_;
      double s = 0;
      for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 5; ++c) s += k_[size_t(r)][size_t(c)] * rows[r][cols[c]];
      o[y * size_t(nx_) + size_t(xi)] = s;
    }
  });
}

SolverResult GeneralizedDiffusion::solve(double c, std::vector<double>* b, double tolerance) const {
  std::vector<double>& x = *b;
  const size_t n = x.size();
  const std::vector<double> rhs = x;  // x starts at b: the undiffused state
  auto op = [&](const std::vector<double>& v, std::vector<double>* out) {  // (I - c A) v
    apply(v, out);
    parallelFor(n, [&](size_t i) { (*out)[i] = v[i] - c * (*out)[i]; }, 4096);
  };
  auto dot = [&](const std::vector<double>& a, const std::vector<double>& b2) {
    return deterministicSum(n, [&](size_t i) { return a[i] * b2[i]; });
  };
  const double diag = 1.0 - c * k_[2][2];
  const double bnorm = std::sqrt(dot(rhs, rhs));
  if (bnorm == 0.0) return SolverResult{true, 0, 0.0};
  std::vector<double> r(n), rhat, p(n, 0.0), v(n, 0.0), y(n), s(n), z(n), t(n);
  op(x, &r);
  parallelFor(n, [&](size_t i) { r[i] = rhs[i] - r[i]; }, 4096);
  rhat = r;
  double rho = 1, alpha = 1, omega = 1;
  double res = std::sqrt(dot(r, r)) / bnorm;
  int it = 0;
  for (; it < 2000 && res > tolerance; ++it) {
    const double rhoNew = dot(rhat, r);
    if (rhoNew == 0.0) break;
    const double beta = (rhoNew / rho) * (alpha / omega);
    rho = rhoNew;
    parallelFor(n, [&](size_t i) {
      p[i] = r[i] + beta * (p[i] - omega * v[i]);
      y[i] = p[i] / diag;
    }, 4096);
    op(y, &v);
    alpha = rho / dot(rhat, v);
    parallelFor(n, [&](size_t i) {
      s[i] = r[i] - alpha * v[i];
      z[i] = s[i] / diag;
    }, 4096);
    op(z, &t);
    const double tt = dot(t, t);
    omega = tt > 0 ? dot(t, s) / tt : 0.0;
    parallelFor(n, [&](size_t i) {
      x[i] += alpha * y[i] + omega * z[i];
      r[i] = s[i] - omega * t[i];
    }, 4096);
    res = std::sqrt(dot(r, r)) / bnorm;
    if (omega == 0.0) break;
  }
  return SolverResult{res <= tolerance, it, res};
}

std::complex<double> GeneralizedDiffusion::symbol(double kx, double ky) const {
  std::complex<double> s = 0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) s += k_[size_t(dy + 2)][size_t(dx + 2)] * std::polar(1.0, kx * dx + ky * dy);
  return s;
}

double GeneralizedDiffusion::spectralRadius(double dtd, double theta) const {
  double worst = 0;
  for (const std::complex<double>& l : symbols_) {
    const double num = std::abs(1.0 + (1.0 - theta) * dtd * l), den = std::abs(1.0 - theta * dtd * l);
    worst = std::max(worst, den > 0 ? num / den : INFINITY);
  }
  return worst;
}

double GeneralizedDiffusion::largestStableStep(double d, double theta, double dtMax, double bound) const {
  if (spectralRadius(dtMax * d, theta) <= bound) return dtMax;
  double lo = 0, hi = dtMax;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (spectralRadius(mid * d, theta) <= bound ? lo : hi) = mid;
  }
  return lo;
}

double gramCharlierPropagator(const KramersMoyalTensors& t, double tau, double rx, double ry) {
  const double x[2] = {rx, ry};
  auto delta = [](int i, int j) { return i == j ? 1.0 : 0.0; };
  // N(0, 2 tau D2)(r)
  const double sxx = 2 * tau * t.d2[0], sxy = 2 * tau * t.d2[1], syy = 2 * tau * t.d2[2];
  const double det = sxx * syy - sxy * sxy;
  if (!(det > 0)) throw std::invalid_argument("the rank-2 tensor must be positive definite");
  const double q = (syy * rx * rx - 2 * sxy * rx * ry + sxx * ry * ry) / det;
  const double gauss = std::exp(-0.5 * q) / (kTwoPi * std::sqrt(det));
  double c3 = 0, c4 = 0;  // D3 . H3 and D4 . H4 (full contractions)
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        const double h3 = x[i] * x[j] * x[k] - (x[i] * delta(j, k) + x[j] * delta(i, k) + x[k] * delta(i, j));
        c3 += component(t.d3, {i, j, k}) * h3;
        for (int l = 0; l < 2; ++l) {
          const double h4 = x[i] * x[j] * x[k] * x[l] -
                            (delta(i, j) * x[k] * x[l] + delta(i, k) * x[j] * x[l] + delta(i, l) * x[j] * x[k] +
                             delta(j, k) * x[i] * x[l] + delta(j, l) * x[i] * x[k] + delta(k, l) * x[i] * x[j]) +
                            (delta(i, j) * delta(k, l) + delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k));
          c4 += component(t.d4, {i, j, k, l}) * h4;
        }
      }
  // Q3 / 3! = -tau D3, Q4 / 4! = tau D4 (eq. 24).
  return gauss * (1.0 - tau * c3 + tau * c4);
}

}  // namespace morphoflow
