// Grid<T, D>: a flat, size-checked, structure-of-arrays field on a regular
// D-dimensional lattice (D = 2, 3). x varies fastest, so one buffer uploads
// unchanged to a GL image or SSBO.
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec.h"

namespace morphoflow {

// The lattice's flat layout, x fastest (shared by Grid and RowField).
template <int D>
size_t latticeIndex(const IVec<D>& dims, const IVec<D>& c) {
  size_t i = size_t(c[D - 1]);
  for (int a = D - 2; a >= 0; --a) i = i * size_t(dims[a]) + size_t(c[a]);
  return i;
}
template <int D>
IVec<D> latticeCoord(const IVec<D>& dims, size_t i) {
  IVec<D> c;
  for (int a = 0; a < D; ++a) {
    c[a] = int(i % size_t(dims[a]));
    i /= size_t(dims[a]);
  }
  return c;
}
// Whether the box of cells [lo, hi) holds none.
template <int D>
bool boxEmpty(const IVec<D>& lo, const IVec<D>& hi) {
  for (int a = 0; a < D; ++a)
    if (hi[a] <= lo[a]) return true;
  return false;
}
// A cell shifted by an offset in {-1, 0, 1}^D, wrapped on every axis; `inside`
// is false when the shift crosses a non-periodic wall.
template <int D>
size_t shiftedIndex(const IVec<D>& dims, const std::array<bool, D>& periodic, IVec<D> c, const IVec<D>& o,
                    bool* inside) {
  size_t idx = 0, stride = 1;
  for (int a = 0; a < D; ++a) {
    int v = c[a] + o[a];
    if (v < 0 || v >= dims[a]) {
      if (!periodic[size_t(a)]) *inside = false;
      v = (v + dims[a]) % dims[a];
    }
    idx += size_t(v) * stride;
    stride *= size_t(dims[a]);
  }
  return idx;
}

// Distance in the flat array between neighbours along `axis`.
template <int D>
size_t latticeStride(const IVec<D>& dims, int axis) {
  size_t s = 1;
  for (int a = 0; a < axis; ++a) s *= size_t(dims[a]);
  return s;
}

template <typename T, int D>
class Grid {
  static_assert(D == 2 || D == 3, "morphoflow grids are 2D or 3D");

 public:
  using value_type = T;

  Grid() = default;
  explicit Grid(IVec<D> dims, T value = T{}) : dims_(dims) {
    size_t n = 1;
    for (int a = 0; a < D; ++a) {
      assert(dims[a] > 0);
      n *= size_t(dims[a]);
    }
    data_.assign(n, value);
  }

  const IVec<D>& dims() const { return dims_; }
  int dim(int axis) const { return dims_[axis]; }
  size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }

  // Linear index of a cell; x fastest.
  size_t index(const IVec<D>& c) const {
    assert(contains(c));
    return latticeIndex<D>(dims_, c);
  }
  IVec<D> coord(size_t i) const { return latticeCoord<D>(dims_, i); }
  size_t stride(int axis) const { return latticeStride<D>(dims_, axis); }
  bool contains(const IVec<D>& c) const {
    for (int a = 0; a < D; ++a)
      if (c[a] < 0 || c[a] >= dims_[a]) return false;
    return true;
  }

  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T& operator()(const IVec<D>& c) { return data_[index(c)]; }
  const T& operator()(const IVec<D>& c) const { return data_[index(c)]; }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

  void fill(T v) { std::fill(data_.begin(), data_.end(), v); }
  // Takes the shape `dims`, its values unspecified; storage is reused (no
  // allocation while the grid has held as many values before).
  void reshape(const IVec<D>& dims) {
    size_t n = 1;
    for (int a = 0; a < D; ++a) n *= size_t(dims[a]);
    dims_ = dims;
    if (data_.capacity() < n) data_.reserve(n);  // (exactly: a lent vector's storage may be another shape's)
    data_.resize(n);
  }

 private:
  IVec<D> dims_{};
  std::vector<T> data_;
};

}  // namespace morphoflow
