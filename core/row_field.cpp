#include "core/row_field.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string_view>

#include "core/parallel.h"

namespace morphoflow {

size_t keepDistinctSegments(float* v, std::vector<size_t>* offset) {
  std::vector<size_t>& off = *offset;
  const size_t rows = off.size() - 1;
  auto bytes = [&](size_t r) { return (off[r + 1] - off[r]) * sizeof(float); };
  // Segments grouped by their hash (in order within a group): each takes the
  // first earlier one of its group that it equals, the same for any thread count.
  std::vector<std::pair<size_t, size_t>> byHash(rows);  // (hash, segment)
  parallelFor(
      rows,
      [&](size_t r) {
        byHash[r] = {std::hash<std::string_view>{}({reinterpret_cast<const char*>(v + off[r]), bytes(r)}), r};
      },
      64);
  std::sort(byHash.begin(), byHash.end());
  std::vector<size_t> same(rows);  // the segment each repeats (itself where none)
  for (size_t g = 0; g < rows;) {
    size_t e = g + 1;
    while (e < rows && byHash[e].first == byHash[g].first) ++e;
    for (size_t j = g; j < e; ++j) {
      const size_t r = byHash[j].second;
      same[r] = r;
      for (size_t m = g; m < j; ++m) {
        const size_t k = byHash[m].second;
        if (same[k] == k && bytes(k) == bytes(r) && std::memcmp(v + off[k], v + off[r], bytes(r)) == 0) {
          same[r] = k;
          break;
        }
      }
    }
    g = e;
  }
  std::vector<size_t> to(rows + 1);
  size_t end = 0;
  bool repeated = false;
  for (size_t r = 0; r < rows; ++r) {
    if (same[r] != r) {
      to[r] = to[same[r]];
      repeated = true;
      continue;
    }
    to[r] = end;
    // Kept segments move down (never up), in order: in place.
    if (end != off[r]) std::memmove(v + end, v + off[r], bytes(r));
    end += off[r + 1] - off[r];
  }
  to[rows] = end;
  if (repeated) off.swap(to);
  return end;
}

float* rowScratch(size_t n) {
  static thread_local std::vector<float> scratch;
  if (scratch.size() < n) scratch.resize(n);
  return scratch.data();
}

bool keepDistinctSegments(std::vector<float>* values, std::vector<size_t>* offset) {
  const size_t before = values->size();
  const size_t end = keepDistinctSegments(values->data(), offset);
  if (end == before) return false;
  values->resize(end);
  values->shrink_to_fit();
  return true;
}

template <int D>
void RowField<D>::compact() {
  if (!dense_) return;
  dense_ = false;
  std::vector<size_t> off(rowOf_.size() + 1);
  for (size_t r = 0; r < off.size(); ++r) off[r] = r * nx_;
  if (keepDistinctSegments(&pool_, &off))
    for (size_t r = 0; r < rowOf_.size(); ++r) rowOf_[r] = uint32_t(off[r] / nx_);
}

template <int D>
void RowField<D>::densify() {
  if (dense_) return;
  pool_ = expanded();
  identity();
}

template <int D>
void RowField<D>::storeRows(const std::vector<size_t>& rows, float* fresh) {
  requireCompact();
  // The rows that changed, moved to the front of fresh and kept once each.
  std::vector<size_t> changed;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (std::memcmp(fresh + k * nx_, row(rows[k]), nx_ * sizeof(float)) == 0) continue;
    if (changed.size() != k) std::memcpy(fresh + changed.size() * nx_, fresh + k * nx_, nx_ * sizeof(float));
    changed.push_back(k);
  }
  if (changed.empty()) return;
  std::vector<size_t> off(changed.size() + 1);
  for (size_t j = 0; j < off.size(); ++j) off[j] = j * nx_;
  const size_t end = keepDistinctSegments(fresh, &off);
  const size_t base = pool_.size();
  pool_.insert(pool_.end(), fresh, fresh + end);
  for (size_t j = 0; j < changed.size(); ++j) rowOf_[rows[changed[j]]] = uint32_t((base + off[j]) / nx_);
  // Stored rows no row uses: dropped once they are most of the pool.
  std::vector<uint32_t> to(storedRows(), UINT32_MAX);
  for (uint32_t s : rowOf_) to[s] = 0;
  const size_t used = size_t(std::count(to.begin(), to.end(), 0u));
  if (2 * used > to.size()) return;
  uint32_t next = 0;
  for (size_t s = 0; s < to.size(); ++s)
    if (to[s] == 0) {
      if (next != s) std::memmove(pool_.data() + size_t(next) * nx_, pool_.data() + s * nx_, nx_ * sizeof(float));
      to[s] = next++;
    }
  pool_.resize(size_t(next) * nx_);  // (its capacity kept for the next rows: an obstacle moves every step)
  for (uint32_t& s : rowOf_) s = to[s];
}

template <int D>
std::vector<float> RowField<D>::expanded() const {
  return expandedRows(0, rowOf_.size());
}

template <int D>
std::vector<float> RowField<D>::expandedRows(size_t begin, size_t end) const {
  std::vector<float> out((end - begin) * nx_);
  parallelFor(
      end - begin, [&](size_t r) { std::memcpy(out.data() + r * nx_, row(begin + r), nx_ * sizeof(float)); }, 64);
  return out;
}

template class RowField<2>;
template class RowField<3>;

}  // namespace morphoflow
