// What a moving solid leaves and takes: the cells (or faces) it uncovers
// take the mean of their neighbours that were fluid before and are now,
// repeated outward a layer at a time; those it covers take a given value
// (the chemicals' solid values) or keep theirs. Which elements are filled,
// in which layer and from which neighbours depends on the solid alone, so a
// FillPlan made once serves every field of a grid, on the CPU (applyFill)
// and the GPU (gpu/fluid/gpu_fill.h), with the formula kernels/extrapolation.inc's.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

namespace detail {
#define EX_FN inline double
#define EX_REAL double
#include "kernels/extrapolation.inc"
#undef EX_FN
#undef EX_REAL
}  // namespace detail

struct FillPlan {
  static constexpr int kLayers = 16;  // how far out the fill reaches
  int stride = 0;                     // entries' uints per element: its index, its count, 2 D neighbour slots
  std::vector<uint32_t> covered;      // the elements the solid covers
  std::vector<uint32_t> entries;      // the uncovered ones, layer after layer
  std::vector<size_t> layerEnds;      // each layer's end, in elements
  bool empty() const { return covered.empty() && entries.empty(); }
};

// The plan of a solid that moved from `was` to `now` (flags: 1 = solid, or held).
template <int D>
FillPlan fillPlan(const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now) {
  FillPlan plan;
  plan.stride = 2 + 2 * D;
  std::vector<size_t> open;  // uncovered, not yet filled
  std::vector<uint8_t> known(was.size(), 0);
  for (size_t i = 0; i < was.size(); ++i) {
    known[i] = !was[i] && !now[i];
    if (was[i] && !now[i]) open.push_back(i);
    if (!was[i] && now[i]) plan.covered.push_back(uint32_t(i));
  }
  const IVec<D> dims = was.dims();
  for (int layer = 0; layer < FillPlan::kLayers && !open.empty(); ++layer) {
    const size_t first = plan.entries.size();
    std::vector<size_t> rest;
    for (size_t i : open) {
      const IVec<D> k = was.coord(i);
      uint32_t e[2 + 2 * D] = {uint32_t(i), 0};
      for (int a = 0; a < D; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[a] += dir;
          if (nb[a] < 0 || nb[a] >= dims[a]) continue;
          const size_t j = was.index(nb);
          if (known[j]) e[2 + e[1]++] = uint32_t(j);
        }
      if (e[1] > 0) plan.entries.insert(plan.entries.end(), e, e + plan.stride);
      else rest.push_back(i);
    }
    // A layer at a time: none of its elements reads another of its own.
    for (size_t q = first; q < plan.entries.size(); q += size_t(plan.stride)) known[plan.entries[q]] = 1;
    plan.layerEnds.push_back(plan.entries.size() / size_t(plan.stride));
    open.swap(rest);
  }
  return plan;
}

// The plan carried out on `values`: the covered elements take `covered`
// (when given), the uncovered their known neighbours' mean.
template <class T>
void applyFill(const FillPlan& plan, T* values, std::optional<T> covered) {
  if (covered)
    for (uint32_t i : plan.covered) values[i] = *covered;
  const size_t stride = size_t(plan.stride);
  for (size_t q = 0; q < plan.entries.size(); q += stride) {
    const uint32_t* e = plan.entries.data() + q;
    double sum = 0.0;
    for (uint32_t k = 0; k < e[1]; ++k) sum += double(values[e[2 + k]]);
    values[e[0]] = T(detail::exNeighbourMean(sum, int(e[1])));
  }
}

}  // namespace morphoflow
