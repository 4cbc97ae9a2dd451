#include "rd/fast_marching.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>

namespace morphoflow {

namespace {

constexpr double kFar = std::numeric_limits<double>::infinity();

// One upwind neighbour per axis: the smaller known distance and where it is.
struct Upwind {
  double d;
  size_t cell;
};

// The eikonal solution from the upwind neighbours (sorted ascending): the
// largest set of axes for which sum_k ((d - a_k) / h)^2 = 1 has d >= every a_k.
double solveEikonal(const std::vector<Upwind>& up, double h, size_t* used) {
  double d = up[0].d + h;
  *used = 1;
  for (size_t m = 2; m <= up.size(); ++m) {
    if (d <= up[m - 1].d) break;
    double s = 0, s2 = 0;
    for (size_t k = 0; k < m; ++k) s += up[k].d, s2 += up[k].d * up[k].d;
    const double disc = s * s - double(m) * (s2 - h * h);
    if (disc < 0) break;
    d = (s + std::sqrt(disc)) / double(m);
    *used = m;
  }
  return d;
}

}  // namespace

template <int D>
MarchingResult fastMarch(const IVec<D>& cells, double h, bool periodic, const MarchingSeeds& seeds) {
  const Grid<char, D> shape(cells);
  const size_t n = shape.size(), channels = seeds.values.size();
  MarchingResult out;
  out.distance.assign(n, kFar);
  out.values.assign(channels, std::vector<double>(n, 0.0));
  std::vector<char> known(n, 0);
  for (size_t q = 0; q < seeds.cells.size(); ++q) {
    const size_t i = seeds.cells[q];
    if (i >= n) throw std::out_of_range("fast marching: a seed outside the grid");
    if (known[i] && out.distance[i] <= seeds.distance[q]) continue;  // a cell seeded twice keeps the nearer seed
    known[i] = 1;
    out.distance[i] = seeds.distance[q];
    for (size_t c = 0; c < channels; ++c) out.values[c][i] = seeds.values[c][q];
  }
  // The neighbour of `c` along axis a in direction s, if any.
  auto neighbour = [&](IVec<D> c, int a, int s, size_t* j) {
    c[a] += s;
    if (c[a] < 0 || c[a] >= cells[a]) {
      if (!periodic) return false;
      c[a] = (c[a] + cells[a]) % cells[a];
    }
    *j = shape.index(c);
    return true;
  };
  using Entry = std::pair<double, size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  std::vector<Upwind> up;
  up.reserve(D);
  auto update = [&](size_t i) {
    const IVec<D> c = shape.coord(i);
    up.clear();
    for (int a = 0; a < D; ++a) {
      Upwind best{kFar, 0};
      for (int s : {-1, 1}) {
        size_t j;
        if (neighbour(c, a, s, &j) && known[j] && out.distance[j] < best.d) best = {out.distance[j], j};
      }
      if (best.d < kFar) up.push_back(best);
    }
    std::sort(up.begin(), up.end(),
              [](const Upwind& x, const Upwind& y) { return x.d < y.d || (x.d == y.d && x.cell < y.cell); });
    size_t used = 0;
    const double d = solveEikonal(up, h, &used);
    if (!(d < out.distance[i])) return;
    out.distance[i] = d;
    // Extension (Adalsteinsson & Sethian eq. 7): grad d . grad v = 0, upwind.
    double wsum = 0;
    for (size_t k = 0; k < used; ++k) wsum += d - up[k].d;
    for (size_t ch = 0; ch < channels; ++ch) {
      double v = 0;
      for (size_t k = 0; k < used; ++k) v += (wsum > 0 ? d - up[k].d : 1.0) * out.values[ch][up[k].cell];
      out.values[ch][i] = v / (wsum > 0 ? wsum : double(used));
    }
    heap.push({d, i});
  };
  auto updateNeighbours = [&](size_t i) {
    const IVec<D> c = shape.coord(i);
    for (int a = 0; a < D; ++a)
      for (int s : {-1, 1}) {
        size_t j;
        if (neighbour(c, a, s, &j) && !known[j]) update(j);
      }
  };
  for (size_t i = 0; i < n; ++i)
    if (known[i]) updateNeighbours(i);
  while (!heap.empty()) {
    const auto [d, i] = heap.top();
    heap.pop();
    if (known[i] || d != out.distance[i]) continue;  // stale entry
    known[i] = 1;
    updateNeighbours(i);
  }
  return out;
}

template MarchingResult fastMarch<2>(const IVec<2>&, double, bool, const MarchingSeeds&);
template MarchingResult fastMarch<3>(const IVec<3>&, double, bool, const MarchingSeeds&);

}  // namespace morphoflow
