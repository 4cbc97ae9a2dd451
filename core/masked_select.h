// Selections by bit masks instead of branches. GCC keeps a branch around an
// IEEE operation that might trap (-ftrapping-math), so a row loop with
// `cond ? 0.0 : a * b` does not vectorise; computing a * b always and
// masking its bits gives the same values, and vectorises.
#pragma once

#include <bit>
#include <cstdint>

namespace morphoflow {

// +0 where `zero`, else v.
inline double zeroWhere(bool zero, double v) {
  return std::bit_cast<double>(std::bit_cast<uint64_t>(v) & (uint64_t(zero) - 1));
}
inline float zeroWhere(bool zero, float v) {
  return std::bit_cast<float>(std::bit_cast<uint32_t>(v) & (uint32_t(zero) - 1));
}
// a where `first`, else b.
inline float pick(bool first, float a, float b) {
  const uint32_t takeB = uint32_t(first) - 1;
  return std::bit_cast<float>((std::bit_cast<uint32_t>(b) & takeB) | (std::bit_cast<uint32_t>(a) & ~takeB));
}

}  // namespace morphoflow
