#include "fluid/probes.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/parallel.h"

namespace morphoflow {

template <int D>
Profile centerlineProfile(const FluidSolver<D>& f, int component, int along, double uref) {
  Profile p;
  const IVec<D>& n = f.cells();
  const double h = f.h();
  Vec<D> centre;
  for (int a = 0; a < D; ++a) centre[a] = 0.5 * n[a] * h;
  const double length = n[along] * h;
  auto sampleAt = [&](double s) {
    Vec<D> x = centre;
    x[along] = s;
    return f.velocity().sample(x)[component] / uref;
  };
  // Wall values: the prescribed wall velocity (no-slip) for a tangential component.
  auto wallValue = [&](bool high) {
    const DomainSide& side = f.settings().boundaries.side(along, high);
    if (side.kind == BoundaryKind::Wall) return side.wallVelocity[size_t(component)] / uref;
    return sampleAt(high ? length : 0.0);
  };
  p.coord.push_back(0.0);
  p.value.push_back(wallValue(false));
  for (int i = 0; i < n[along]; ++i) {
    double s = (i + 0.5) * h;
    p.coord.push_back(s / length);
    p.value.push_back(sampleAt(s));
  }
  p.coord.push_back(1.0);
  p.value.push_back(wallValue(true));
  return p;
}

template <int D>
std::array<double, 3> obstacleForce(const FluidSolver<D>& f) {
  std::array<double, 3> force{0, 0, 0};
  const VelocityConstraints<D>& vc = f.constraints();
  const Grid<uint8_t, D>& solid = f.solid();
  const Grid<float, D> p = f.pressure();
  const IVec<D>& n = f.cells();
  const double h = f.h();
  const double area = std::pow(h, D - 1);
  const double mu = f.settings().density * f.settings().viscosity;
  // The staircase obstacles' cells (the cut ones' surface is integrated below).
  auto staircase = [&](size_t i) {
    if (!solid[i]) return false;
    if (vc.cut.empty()) return true;
    const IVec<D> k = solid.coord(i);
    double c[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) c[a] = (k[a] + 0.5) * h;
    return !(vc.cut.distance(c) < 0.0);
  };
  for (int a = 0; a < D; ++a) {
    for (int dir = -1; dir <= 1; dir += 2) {
      // Each component summed deterministically over the solid cells.
      for (int b = 0; b < D; ++b) {
        force[size_t(b)] += deterministicSum(solid.size(), [&](size_t i) -> double {
          if (!staircase(i)) return 0.0;
          IVec<D> s = solid.coord(i);
          IVec<D> fl = s;
          fl[a] += dir;
          if (fl[a] < 0 || fl[a] >= n[a] || solid(fl)) return 0.0;
          if (b == a) return -double(p(fl)) * dir * area;     // pressure along the normal
          double ut = f.velocity().atCell(fl)[b];
          if (vc.bodies.moving()) {  // relative to the wall
            double x[3] = {0, 0, 0};
            for (int c = 0; c < D; ++c) x[c] = (fl[c] + 0.5) * h - (c == a ? dir * 0.5 * h : 0.0);
            ut -= vc.bodies.velocity(x)[size_t(b)];
          }
          return mu * ut / (0.5 * h) * area;                    // shear along the wall
        });
      }
    }
  }
  const std::array<double, 3> cut = surfaceForce<D>(f.cutSurface(), f.velocity(), p, mu, &vc.bodies);
  for (int b = 0; b < 3; ++b) force[size_t(b)] += cut[size_t(b)];
  return force;
}

StrouhalEstimate estimateStrouhal(const std::vector<double>& t, const std::vector<double>& y,
                                  double tStart, double length, double speed) {
  StrouhalEstimate e;
  std::vector<double> ts, ys;
  for (size_t i = 0; i < t.size() && i < y.size(); ++i)
    if (t[i] >= tStart) {
      ts.push_back(t[i]);
      ys.push_back(y[i]);
    }
  if (ts.size() < 4) return e;
  double mean = std::accumulate(ys.begin(), ys.end(), 0.0) / double(ys.size());
  std::vector<double> crossings;
  for (size_t i = 1; i < ts.size(); ++i) {
    double a = ys[i - 1] - mean, b = ys[i] - mean;
    if (a < 0 && b >= 0) crossings.push_back(ts[i - 1] + (ts[i] - ts[i - 1]) * (-a) / (b - a));
  }
  if (crossings.size() < 2) return e;
  std::vector<double> periods;
  for (size_t i = 1; i < crossings.size(); ++i) periods.push_back(crossings[i] - crossings[i - 1]);
  double mp = std::accumulate(periods.begin(), periods.end(), 0.0) / double(periods.size());
  auto [mn, mx] = std::minmax_element(periods.begin(), periods.end());
  e.periods = int(periods.size());
  e.frequency = 1.0 / mp;
  e.strouhal = e.frequency * length / speed;
  e.periodSpread = (*mx - *mn) / mp;
  for (double T : periods) e.periodStrouhal.push_back(length / (T * speed));
  return e;
}

std::vector<double> windowMean(const std::vector<double>& t, const std::vector<double>& y, double window) {
  // Sample j stands for its step (t[j-1], t[j]]: the mean is the integral of
  // that step function over [t - window / 2, t + window / 2] (cut at the
  // series' ends), over the window's length there.
  const size_t n = std::min(t.size(), y.size());
  std::vector<double> out(n);
  auto stepStart = [&](size_t j) { return j > 0 ? t[j - 1] : (n > 1 ? 2 * t[0] - t[1] : t[0]); };
  size_t first = 0;
  for (size_t i = 0; i < n; ++i) {
    const double a = t[i] - 0.5 * window, b = t[i] + 0.5 * window;
    while (first < n && t[first] <= a) ++first;
    double sum = 0.0, length = 0.0;
    for (size_t j = first; j < n && stepStart(j) < b; ++j) {
      const double overlap = std::min(b, t[j]) - std::max(a, stepStart(j));
      if (overlap > 0) sum += overlap * y[j], length += overlap;
    }
    out[i] = length > 0 ? sum / length : y[i];
  }
  return out;
}

template <int D>
Grid<float, D> speedField(const FluidSolver<D>& f) {
  Grid<float, D> s(f.cells(), 0.0f);
  forEachCell<D>(f.cells(), [&](const IVec<D>& k, size_t i) {
    Vec<D> v = f.velocity().atCell(k);
    double m = 0;
    for (int a = 0; a < D; ++a) m += v[a] * v[a];
    s[i] = float(std::sqrt(m));
  });
  return s;
}

template <int D>
Grid<float, D> vorticityField(const FluidSolver<D>& f) {
  Grid<float, D> w(f.cells(), 0.0f);
  const IVec<D>& n = f.cells();
  const double h = f.h();
  const MacVelocity<D>& u = f.velocity();
  // d u_b / d x_a at a cell, central differences of cell-centred velocity.
  auto deriv = [&](const IVec<D>& k, int b, int a) {
    IVec<D> lo = k, hi = k;
    lo[a] = std::max(0, k[a] - 1);
    hi[a] = std::min(n[a] - 1, k[a] + 1);
    if (hi[a] == lo[a]) return 0.0;
    return (u.atCell(hi)[b] - u.atCell(lo)[b]) / ((hi[a] - lo[a]) * h);
  };
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    if (f.solid()[i]) return;
    if constexpr (D == 2) {
      w[i] = float(deriv(k, 1, 0) - deriv(k, 0, 1));
    } else {
      double wx = deriv(k, 2, 1) - deriv(k, 1, 2);
      double wy = deriv(k, 0, 2) - deriv(k, 2, 0);
      double wz = deriv(k, 1, 0) - deriv(k, 0, 1);
      w[i] = float(std::sqrt(wx * wx + wy * wy + wz * wz));
    }
  });
  return w;
}

template Profile centerlineProfile<2>(const FluidSolver<2>&, int, int, double);
template Profile centerlineProfile<3>(const FluidSolver<3>&, int, int, double);
template std::array<double, 3> obstacleForce<2>(const FluidSolver<2>&);
template std::array<double, 3> obstacleForce<3>(const FluidSolver<3>&);
template Grid<float, 2> speedField<2>(const FluidSolver<2>&);
template Grid<float, 3> speedField<3>(const FluidSolver<3>&);
template Grid<float, 2> vorticityField<2>(const FluidSolver<2>&);
template Grid<float, 3> vorticityField<3>(const FluidSolver<3>&);

}  // namespace morphoflow
