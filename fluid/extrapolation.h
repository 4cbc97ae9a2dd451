// What a moving solid leaves and takes: the cells (or faces) it uncovers
// take the mean of their neighbours that were fluid before and are now,
// repeated outward a layer at a time; those it covers take a given value
// (the chemicals' solid values) or keep theirs. Which elements are filled,
// in which layer and from which neighbours depends on the solid alone, so a
// FillPlan made once serves every field of a grid, on the CPU (applyFill)
// and the GPU (gpu/fluid/gpu_fill.h), with the formula kernels/extrapolation.inc's.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
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

// The plan of a solid that moved from `was` to `now` (flags: 1 = solid, or
// held), which differ only in the box [lo, hi): the elements in it are
// scanned, and an element outside counts as fluid where `now` says so.
template <int D>
FillPlan fillPlan(const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now, IVec<D> lo, IVec<D> hi) {
  FillPlan plan;
  plan.stride = 2 + 2 * D;
  const IVec<D> dims = was.dims();
  for (int a = 0; a < D; ++a) lo[a] = std::clamp(lo[a], 0, dims[a]), hi[a] = std::clamp(hi[a], lo[a], dims[a]);
  const IVec<D> box = hi - lo;
  auto inBox = [&](const IVec<D>& k) {  // k's index in the box, or SIZE_MAX
    for (int a = 0; a < D; ++a)
      if (k[a] < lo[a] || k[a] >= hi[a]) return SIZE_MAX;
    return latticeIndex<D>(box, k - lo);
  };
  std::vector<std::pair<size_t, size_t>> open;  // uncovered, not yet filled: index, index in the box
  size_t boxCells = 1;
  for (int a = 0; a < D; ++a) boxCells *= size_t(box[a]);
  for (size_t b = 0; b < boxCells; ++b) {  // in index order
    const size_t i = was.index(lo + latticeCoord<D>(box, b));
    if (was[i] && !now[i]) open.emplace_back(i, b);
    if (!was[i] && now[i]) plan.covered.push_back(uint32_t(i));
  }
  std::vector<uint8_t> filled(boxCells, 0);  // by an earlier layer
  auto known = [&](const IVec<D>& k, size_t j) {
    if (!was[j] && !now[j]) return true;
    const size_t b = inBox(k);
    return b != SIZE_MAX && filled[b] != 0;
  };
  for (int layer = 0; layer < FillPlan::kLayers && !open.empty(); ++layer) {
    std::vector<std::pair<size_t, size_t>> rest;
    std::vector<size_t> done;
    for (const auto& [i, b] : open) {
      const IVec<D> k = was.coord(i);
      uint32_t e[2 + 2 * D] = {uint32_t(i), 0};
      for (int a = 0; a < D; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[a] += dir;
          if (nb[a] < 0 || nb[a] >= dims[a]) continue;
          const size_t j = was.index(nb);
          if (known(nb, j)) e[2 + e[1]++] = uint32_t(j);
        }
      if (e[1] > 0) {
        plan.entries.insert(plan.entries.end(), e, e + plan.stride);
        done.push_back(b);
      } else {
        rest.emplace_back(i, b);
      }
    }
    // A layer at a time: none of its elements reads another of its own.
    for (size_t b : done) filled[b] = 1;
    plan.layerEnds.push_back(plan.entries.size() / size_t(plan.stride));
    open.swap(rest);
  }
  return plan;
}

// The same over the whole grid.
template <int D>
FillPlan fillPlan(const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now) {
  return fillPlan<D>(was, now, IVec<D>(0), was.dims());
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
