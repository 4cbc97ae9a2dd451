// RowField<D>: a float field on a grid whose rows (the cells along x of one
// y (, z)) are stored once per distinct content. The coefficient fields of
// the linear systems are uniform almost everywhere (weight 1 inside, 0
// across a wall, one identity term), so a box keeps a handful of rows however
// fine its grid, and an obstacle's rows are kept as they are: the same values
// and the same kernels (they read a row at a time), a few bytes instead of
// four a cell.
//
// A field is written while dense (just constructed, or after densify()), then
// compact() keeps each distinct row once; reading works in both states.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <cstdint>
#include <vector>

#include "core/grid.h"
#include "core/parallel.h"

namespace morphoflow {

// Keeps each distinct segment of *values once: segment r is [offset[r],
// offset[r + 1]); afterwards offset[r] is where its content starts in the
// shortened *values (compared bitwise; the first of equal segments is kept,
// independent of the thread count). Returns whether anything repeated.
bool keepDistinctSegments(std::vector<float>* values, std::vector<size_t>* offset);
// The same in place on the segments at `values`; returns where the kept ones end.
size_t keepDistinctSegments(float* values, std::vector<size_t>* offset);

template <int D>
class RowField {
 public:
  RowField() = default;
  RowField(const IVec<D>& dims, float value) : RowField(dims) {
    pool_.assign(size_, value);
    identity();
  }

  const IVec<D>& dims() const { return dims_; }
  int dim(int axis) const { return dims_[axis]; }
  size_t size() const { return size_; }
  size_t index(const IVec<D>& c) const { return latticeIndex<D>(dims_, c); }  // Grid's order
  IVec<D> coord(size_t i) const { return latticeCoord<D>(dims_, i); }
  size_t stride(int axis) const { return latticeStride<D>(dims_, axis); }

  // Row r's nx values.
  const float* row(size_t r) const { return pool_.data() + size_t(rowOf_[r]) * nx_; }
  float operator[](size_t i) const {
    if (dense_) return pool_[i];
    size_t r = size_t(double(i) * invNx_);  // i / nx, corrected below (a division costs far more)
    r -= r * nx_ > i;
    r += (r + 1) * nx_ <= i;
    return pool_[size_t(rowOf_[r]) * nx_ + (i - r * nx_)];
  }
  float operator()(const IVec<D>& c) const { return (*this)[index(c)]; }

  // Writing: only while dense.
  bool dense() const { return dense_; }
  float& at(size_t i) {
    requireDense();
    return pool_[i];
  }
  float* mutableRow(size_t r) {
    requireDense();
    return pool_.data() + r * nx_;
  }
  void fill(float v) {
    requireDense();
    std::fill(pool_.begin(), pool_.end(), v);
  }
  // A field whose row r, compute(r, out), depends only on the rows
  // sources(r) of other fields (an array of K row pointers): each distinct
  // combination of source rows is computed once, with no dense copy.
  template <size_t K, class Sources, class Compute>
  static RowField fromSources(const IVec<D>& dims, Sources&& sources, Compute&& compute) {
    RowField f(dims);
    std::map<std::array<uintptr_t, K>, uint32_t> ids;  // source rows -> stored row, in order of first use
    std::vector<size_t> first;
    for (size_t r = 0; r < f.rowOf_.size(); ++r) {
      const std::array<const float*, K> src = sources(r);
      std::array<uintptr_t, K> key;
      for (size_t k = 0; k < K; ++k) key[k] = reinterpret_cast<uintptr_t>(src[k]);
      const auto [it, added] = ids.emplace(key, uint32_t(first.size()));
      if (added) first.push_back(r);
      f.rowOf_[r] = it->second;
    }
    f.pool_.resize(first.size() * f.nx_);
    parallelFor(first.size(), [&](size_t k) { compute(first[k], f.pool_.data() + k * f.nx_); });
    f.dense_ = false;
    return f;
  }
  // Keeps each distinct row once (rows compared bitwise; the first of equal
  // rows is kept, so the result does not depend on the thread count).
  void compact();
  // Back to one row per row, writable.
  void densify();
  // Rows `rows` of a compact field take new values, fresh[k nx ..] for rows[k]
  // (rewriteRows() below; fresh is scratch, overwritten): a row that comes
  // out as it was keeps its stored row, equal new rows share one; stored
  // rows no row uses any more are dropped once they are most of them. The
  // values read are the dense field's after the same writes, whatever rows
  // end up shared.
  void storeRows(const std::vector<size_t>& rows, float* fresh);
  // v -> f(v) on every value, applied to the stored rows only.
  template <class F>
  void transform(F&& f) {
    for (float& v : pool_) v = f(v);
  }
  // Every value, in grid order (a GPU upload's copy); those of rows [begin, end).
  std::vector<float> expanded() const;
  std::vector<float> expandedRows(size_t begin, size_t end) const;
  // Rows stored (the footprint is storedRows() * nx floats plus 4 bytes a row).
  size_t storedRows() const { return pool_.size() / (nx_ ? nx_ : 1); }
  // The stored row that row r reads (< storedRows()).
  uint32_t storedRow(size_t r) const { return rowOf_[r]; }
  const float* stored(uint32_t k) const { return pool_.data() + size_t(k) * nx_; }

 private:
  explicit RowField(const IVec<D>& dims) : dims_(dims) {  // shaped, no rows yet
    nx_ = size_t(dims[0]);
    invNx_ = 1.0 / double(nx_);
    size_ = 1;
    for (int a = 0; a < D; ++a) size_ *= size_t(dims[a]);
    rowOf_.resize(size_ / nx_);
  }
  void requireCompact() const {
    if (dense_) throw std::logic_error("RowField: storeRows() on a dense field (write it in place)");
  }
  void requireDense() const {
    if (!dense_) throw std::logic_error("RowField: written after compact() (densify() it first)");
  }
  void identity() {
    rowOf_.resize(nx_ ? size_ / nx_ : 0);
    for (size_t r = 0; r < rowOf_.size(); ++r) rowOf_[r] = uint32_t(r);
    dense_ = true;
  }

  IVec<D> dims_{};
  size_t nx_ = 0, size_ = 0;
  double invNx_ = 0.0;
  std::vector<float> pool_;        // the stored rows, nx values each
  std::vector<uint32_t> rowOf_;    // row -> its stored row
  bool dense_ = false;
};

// The rows (along x) that cross the box [lo, hi) of a grid of `dims`, ascending.
template <int D>
std::vector<size_t> rowsOf(const IVec<D>& dims, const IVec<D>& lo, const IVec<D>& hi) {
  std::vector<size_t> rows;
  if (boxEmpty<D>(lo, hi)) return rows;
  const int zlo = D == 3 ? lo[D - 1] : 0, zhi = D == 3 ? hi[D - 1] : 1;
  for (int z = zlo; z < zhi; ++z)
    for (int y = lo[1]; y < hi[1]; ++y) rows.push_back(size_t(y) + (D == 3 ? size_t(z) * size_t(dims[1]) : 0));
  return rows;
}

// The rows [first, last] of `rows` (ascending), as [begin, end); {0, 0} when there are none.
inline std::pair<size_t, size_t> rowSpan(const std::vector<size_t>& rows) {
  return rows.empty() ? std::pair<size_t, size_t>{0, 0} : std::pair<size_t, size_t>{rows.front(), rows.back() + 1};
}

// At least n floats of the calling thread's scratch for rewriteRows, kept
// from call to call (a moving obstacle's rows, every step): no allocation,
// no zeros written first. Valid until the thread's next call.
float* rowScratch(size_t n);

// Rows `rows` of fields of one shape written again: write(r, v) changes
// row r's values of field q in v[q] (given as they are). A dense field is
// written in place; a compact one stays compact (RowField::storeRows), so
// a few rows change without a pass over the whole field. The rows are
// written in parallel, each once.
template <int D, size_t K, class Write>
void rewriteRows(const std::array<RowField<D>*, K>& fields, const std::vector<size_t>& rows, Write&& write) {
  const size_t nx = size_t(fields[0]->dim(0)), block = rows.size() * nx;
  size_t compact = 0;  // (dense fields are written in place)
  for (size_t q = 0; q < K; ++q) compact += fields[q]->dense() ? 0 : 1;
  float* const scratch = rowScratch(compact * block);
  std::array<float*, K> at{};  // each compact field's block of scratch
  for (size_t q = 0, j = 0; q < K; ++q)
    if (!fields[q]->dense()) at[q] = scratch + block * j++;
  parallelFor(rows.size(), [&](size_t k) {
    std::array<float*, K> v;
    for (size_t q = 0; q < K; ++q) {
      if (fields[q]->dense()) {
        v[q] = fields[q]->mutableRow(rows[k]);
      } else {
        v[q] = at[q] + k * nx;
        std::copy_n(fields[q]->row(rows[k]), nx, v[q]);
      }
    }
    write(rows[k], v);
  });
  for (size_t q = 0; q < K; ++q)
    if (!fields[q]->dense()) fields[q]->storeRows(rows, at[q]);
}

}  // namespace morphoflow
