// What a moving solid leaves and takes: the cells (or faces) it uncovers
// take the mean of their neighbours that were fluid before and are now,
// repeated outward a layer at a time; those it covers take `covered`
// (when given). `was` and `now` flag the solid (held) cells before and
// after the solid moved.
#pragma once

#include <optional>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

template <class T, int D>
void fillUncovered(Grid<T, D>* g, const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now, std::optional<T> covered) {
  std::vector<size_t> open;  // uncovered, not yet filled
  std::vector<uint8_t> known(g->size(), 0);
  for (size_t i = 0; i < g->size(); ++i) {
    known[i] = !was[i] && !now[i];
    if (was[i] && !now[i]) open.push_back(i);
    if (!was[i] && now[i] && covered) (*g)[i] = *covered;
  }
  const IVec<D> dims = g->dims();
  for (int layer = 0; layer < 16 && !open.empty(); ++layer) {
    std::vector<std::pair<size_t, T>> filled;
    std::vector<size_t> rest;
    for (size_t i : open) {
      const IVec<D> k = g->coord(i);
      double sum = 0.0;
      int count = 0;
      for (int a = 0; a < D; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[a] += dir;
          if (nb[a] < 0 || nb[a] >= dims[a]) continue;
          const size_t j = g->index(nb);
          if (known[j]) sum += double((*g)[j]), ++count;
        }
      if (count > 0) filled.emplace_back(i, T(sum / count));
      else rest.push_back(i);
    }
    for (const auto& [i, v] : filled) (*g)[i] = v, known[i] = 1;  // a layer at a time: the order does not matter
    open.swap(rest);
  }
}

}  // namespace morphoflow
