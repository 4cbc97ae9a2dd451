#include "core/row_field.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string_view>
#include <unordered_map>

#include "core/parallel.h"

namespace morphoflow {

bool keepDistinctSegments(std::vector<float>* values, std::vector<size_t>* offset) {
  std::vector<float>& v = *values;
  std::vector<size_t>& off = *offset;
  const size_t rows = off.size() - 1;
  auto bytes = [&](size_t r) { return (off[r + 1] - off[r]) * sizeof(float); };
  std::vector<size_t> hash(rows);
  parallelFor(rows, [&](size_t r) {
    hash[r] = std::hash<std::string_view>{}({reinterpret_cast<const char*>(v.data() + off[r]), bytes(r)});
  }, 64);
  // Serial, in order: which segment each repeats is the same for any thread count.
  std::unordered_map<size_t, std::vector<size_t>> kept;  // hash -> segments kept
  std::vector<size_t> to(rows + 1), keep;
  size_t end = 0;
  for (size_t r = 0; r < rows; ++r) {
    std::vector<size_t>& same = kept[hash[r]];
    auto match = std::find_if(same.begin(), same.end(), [&](size_t k) {
      return bytes(k) == bytes(r) && std::memcmp(v.data() + off[k], v.data() + off[r], bytes(r)) == 0;
    });
    if (match != same.end()) {
      to[r] = to[*match];
      continue;
    }
    same.push_back(r);
    keep.push_back(r);
    to[r] = end;
    end += off[r + 1] - off[r];
  }
  to[rows] = end;
  if (keep.size() == rows) return false;
  // Kept segments move down (never up), in order: in place.
  for (size_t r : keep) std::memmove(v.data() + to[r], v.data() + off[r], bytes(r));
  v.resize(end);
  v.shrink_to_fit();
  off.swap(to);
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
void RowField<D>::storeRows(const std::vector<size_t>& rows, std::vector<float>* fresh) {
  requireCompact();
  std::vector<float>& f = *fresh;
  // The rows that changed, their new values gathered and kept once each.
  std::vector<size_t> changed;
  for (size_t k = 0; k < rows.size(); ++k)
    if (std::memcmp(f.data() + k * nx_, row(rows[k]), nx_ * sizeof(float)) != 0) changed.push_back(k);
  if (changed.empty()) return;
  std::vector<float> block(changed.size() * nx_);
  for (size_t j = 0; j < changed.size(); ++j) std::copy_n(f.data() + changed[j] * nx_, nx_, block.data() + j * nx_);
  std::vector<size_t> off(changed.size() + 1);
  for (size_t j = 0; j < off.size(); ++j) off[j] = j * nx_;
  keepDistinctSegments(&block, &off);
  const size_t base = pool_.size();
  pool_.insert(pool_.end(), block.begin(), block.end());
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
