#include "core/simd_dispatch.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace morphoflow {

namespace {

bool detect() {
#if MORPHOFLOW_AVX2_KERNELS
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

bool initial() {
  const char* v = std::getenv("MORPHOFLOW_SIMD");
  if (v && std::strcmp(v, "4") == 0) return false;
  return cpuHasAvx2();
}

std::atomic<bool>& flag() {
  static std::atomic<bool> on{initial()};
  return on;
}

}  // namespace

bool cpuHasAvx2() {
  static const bool has = detect();
  return has;
}

bool useAvx2() { return flag().load(std::memory_order_relaxed); }

void setUseAvx2(bool on) { flag().store(on && cpuHasAvx2(), std::memory_order_relaxed); }

}  // namespace morphoflow
