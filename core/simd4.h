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

}  // namespace morphoflow
