// Where a step runs (--backend): TBB tasks, one thread (the coupled step's
// serial schedule), or OpenGL compute (gpu/).
#pragma once

#include <stdexcept>
#include <string>

namespace morphoflow {

enum class Backend { TBB, Serial, Gpu };

// The GPU's storage and arithmetic for its solver vectors, pressure and
// reaction-diffusion layer (gpu.precision; docs/gpu.md "Precision"); sums are
// accumulated in double either way.
enum class GpuPrecision { Float, Double };

inline const char* precisionName(GpuPrecision p) { return p == GpuPrecision::Float ? "float" : "double"; }

// "tbb", "serial" or "gpu"; std::invalid_argument for any other name.
inline Backend backendNamed(const std::string& name) {
  if (name == "tbb") return Backend::TBB;
  if (name == "serial") return Backend::Serial;
  if (name == "gpu") return Backend::Gpu;
  throw std::invalid_argument("no backend '" + name + "'");
}

}  // namespace morphoflow
