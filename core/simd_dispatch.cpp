#include "core/simd_dispatch.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace morphoflow {

namespace {

bool detect(const char* feature) {
#if MORPHOFLOW_AVX2_KERNELS
  __builtin_cpu_init();
  if (std::strcmp(feature, "avx512") == 0)
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return __builtin_cpu_supports("avx2");
#else
  (void)feature;
  return false;
#endif
}

// The widest lanes MORPHOFLOW_SIMD allows: 4, 8 or (unset) any.
int simdLimit() {
  const char* v = std::getenv("MORPHOFLOW_SIMD");
  if (v && std::strcmp(v, "4") == 0) return 4;
  if (v && std::strcmp(v, "8") == 0) return 8;
  return 16;
}

std::atomic<bool>& flag() {
  static std::atomic<bool> on{simdLimit() > 4 && cpuHasAvx2()};
  return on;
}

std::atomic<bool>& flag512() {
  static std::atomic<bool> on{simdLimit() > 8 && cpuHasAvx512()};
  return on;
}

}  // namespace

bool cpuHasAvx2() {
  static const bool has = detect("avx2");
  return has;
}

bool cpuHasAvx512() {
  static const bool has = detect("avx512");
  return has;
}

bool useAvx512() { return useAvx2() && flag512().load(std::memory_order_relaxed); }

void setUseAvx512(bool on) { flag512().store(on && cpuHasAvx512(), std::memory_order_relaxed); }

bool useAvx2() { return flag().load(std::memory_order_relaxed); }

void setUseAvx2(bool on) { flag().store(on && cpuHasAvx2(), std::memory_order_relaxed); }

}  // namespace morphoflow
