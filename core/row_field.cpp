#include "core/row_field.h"

#include <cstring>
#include <functional>
#include <string_view>
#include <unordered_map>

#include "core/parallel.h"

namespace morphoflow {

template <int D>
void RowField<D>::compact() {
  if (!dense_) return;
  dense_ = false;
  const size_t rows = rowOf_.size(), bytes = nx_ * sizeof(float);
  std::vector<size_t> hash(rows);
  parallelFor(rows, [&](size_t r) {
    hash[r] = std::hash<std::string_view>{}({reinterpret_cast<const char*>(pool_.data() + r * nx_), bytes});
  }, 64);
  // Distinct rows in order of first appearance (serial: the ids, hence the
  // layout, do not depend on the thread count).
  std::unordered_map<size_t, std::vector<uint32_t>> byHash;
  std::vector<size_t> first;  // stored row -> the row it copies
  for (size_t r = 0; r < rows; ++r) {
    std::vector<uint32_t>& ids = byHash[hash[r]];
    const float* v = pool_.data() + r * nx_;
    uint32_t id = uint32_t(first.size());
    for (uint32_t k : ids)
      if (std::memcmp(pool_.data() + first[k] * nx_, v, bytes) == 0) id = k;
    if (id == first.size()) {
      ids.push_back(id);
      first.push_back(r);
    }
    rowOf_[r] = id;
  }
  if (first.size() == rows) return;  // nothing repeats: keep the rows in place
  std::vector<float> pool(first.size() * nx_);
  for (size_t k = 0; k < first.size(); ++k)
    std::memcpy(pool.data() + k * nx_, pool_.data() + first[k] * nx_, bytes);
  pool_.swap(pool);
}

template <int D>
void RowField<D>::densify() {
  if (dense_) return;
  pool_ = expanded();
  identity();
}

template <int D>
std::vector<float> RowField<D>::expanded() const {
  std::vector<float> out(size_);
  parallelFor(rowOf_.size(), [&](size_t r) { std::memcpy(out.data() + r * nx_, row(r), nx_ * sizeof(float)); }, 64);
  return out;
}

template class RowField<2>;
template class RowField<3>;

}  // namespace morphoflow
