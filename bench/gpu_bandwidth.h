// The GPU suites' shared pieces: the device's peak memory bandwidth (for the
// "of peak" column), its measured copy bandwidth (the "of copy" one) and the
// table header naming the device.
#pragma once

#include <cstdlib>
#include <iostream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/bench_suites.h"
#include "core/error.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_copy_bandwidth.h"
#include "gpu/gpu_newton_check.h"

namespace morphoflow {

// Peak memory bandwidth in GB/s of the renderer, 0 when unknown
// (MORPHOFLOW_GPU_PEAK_GBS gives it for any device).
inline double peakBandwidth(const std::string& renderer) {
  if (const char* env = std::getenv("MORPHOFLOW_GPU_PEAK_GBS")) return std::atof(env);
  if (renderer.find("H200") != std::string::npos) return 4800;
  if (renderer.find("H100") != std::string::npos) return renderer.find("PCIe") != std::string::npos ? 2000 : 3350;
  if (renderer.find("A100") != std::string::npos) return 2039;
  return 0;
}

// The device's peak bandwidth (the data sheet's, 0: unknown) and its copy bandwidth (measured).
struct GpuBandwidth {
  double peak = 0.0, copy = 0.0;
};

// The context (exit 2 without one), after printing the device, its peak and its measured copy bandwidth.
inline GpuBandwidth announceGpu(GpuPrecision real) {
  const GlContext* context = nullptr;
  try {
    context = &GlContext::instance();
  } catch (const GpuUnavailable& e) {
    throw UserError({"--backend", 0, 0}, "", std::string("no usable GPU context: ") + e.what(), "bench on the CPU");
  }
  const double peak = peakBandwidth(context->renderer());
  std::cout << fmt::format(
      "gpu: {}, OpenGL {}; peak bandwidth {}\n", context->renderer(), context->version(),
      peak > 0 ? fmt::format("{:.0f} GB/s", peak) : std::string("unknown (set MORPHOFLOW_GPU_PEAK_GBS)"));
  // 256 MiB a buffer on a GPU (well past its caches), 16 MiB on llvmpipe
  const bool emulated = context->renderer().find("llvmpipe") != std::string::npos;
  const double copy = measureCopyBandwidth(emulated ? size_t(16) << 20 : size_t(256) << 20);
  std::cout << fmt::format("copy bandwidth: {:.0f} GB/s (measured: read and write once){}\n", copy,
                           peak > 0 ? fmt::format(", {:.0f}% of the peak", 100 * copy / peak) : std::string());
  std::cout << "precision: " << precisionName(real) << " (--precision)\n";
  // The suites' Kim & Lin rows step Gray-Scott's Newton: say when this driver gets it wrong (gpu/gpu_newton_check.h).
  if (const std::string defect = gpuNewtonDefect("gray-scott", real); !defect.empty())
    std::cout << "warning: this driver computes Kim & Lin's Newton wrongly in " << precisionName(real) << " (" << defect
              << "): its kim-lin and coupling rows time a failing Newton\n";
  return {peak, copy};
}

// A row's GB/s as fractions of the peak and of the measured copy bandwidth (its JSON).
inline void addBandwidthFractions(nlohmann::json* row, const GpuBandwidth& bw) {
  const double gbs = (*row)["gb_per_second"].get<double>();
  if (bw.peak > 0) (*row)["fraction_of_peak_bandwidth"] = gbs / bw.peak;
  if (bw.copy > 0) (*row)["fraction_of_copy_bandwidth"] = gbs / bw.copy;
}

// The GPU suites' precision (--precision; float unless double).
inline GpuPrecision benchPrecision(const BenchOptions& o) {
  return o.precision == "double" ? GpuPrecision::Double : GpuPrecision::Float;
}

inline std::string ofPeak(double gbs, double peak) {
  return peak > 0 ? fmt::format("{:.0f}%", 100 * gbs / peak) : std::string("-");
}

}  // namespace morphoflow
