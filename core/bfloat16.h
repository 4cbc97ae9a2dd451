// bfloat16: a float's sign, exponent and top 7 mantissa bits in 16 bits
// (relative precision 2^-8, float's range). For values that are only a
// small correction to a float (a warm start's second difference), where
// half the storage costs nothing that matters.
#pragma once

#include <bit>
#include <cstdint>

namespace morphoflow {

// Rounded to nearest, ties to even (finite inputs).
inline uint16_t toBfloat16(float f) {
  const uint32_t b = std::bit_cast<uint32_t>(f);
  return uint16_t((b + 0x7FFFu + ((b >> 16) & 1u)) >> 16);
}

inline float fromBfloat16(uint16_t h) { return std::bit_cast<float>(uint32_t(h) << 16); }

}  // namespace morphoflow
