// Counter-based random numbers: value = hash(seed, stream, index). Any cell
// can draw its number independently, so results never depend on the thread
// count or the order of evaluation (SplitMix64 finaliser, Steele et al. 2014).
#pragma once

#include <cstdint>

namespace morphoflow {

inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Uniform in [0, 1) for (seed, stream, index).
inline double uniform01(uint64_t seed, uint64_t stream, uint64_t index) {
  uint64_t h = mix64(mix64(seed ^ mix64(stream)) + index);
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

}  // namespace morphoflow
