// Four floats at a time through GCC vector extensions: one SSE2 register,
// the x86-64 baseline, so no -march flag is needed. Lanes follow IEEE float
// arithmetic one for one, so a kernel written on vf4 gives bitwise the
// scalar loop's results.
#pragma once

#include <cstring>

namespace morphoflow {

typedef float vf4 __attribute__((vector_size(16)));
typedef int vi4 __attribute__((vector_size(16)));
constexpr int kLanes = 4;

inline vf4 load4(const float* p) {  // unaligned
  vf4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(float* p, vf4 v) { std::memcpy(p, &v, sizeof v); }
inline vf4 splat(float v) { return vf4{} + v; }

// Lanes of two vectors picked by index (0-3: a, 4-7: b), for GCC and clang alike.
#if defined(__clang__)
#define MF_SHUFFLE(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define MF_SHUFFLE(a, b, i, j, k, l) __builtin_shuffle(a, b, vi4{i, j, k, l})
#endif

}  // namespace morphoflow
