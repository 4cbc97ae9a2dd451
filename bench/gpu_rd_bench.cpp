// `bench rd --backend gpu`: cell updates per second of the explicit
// Gray-Scott step on the GPU (gpu/gpu_explicit_rd.h), the same start and dt
// as the CPU suite; 2D 256^2..4096^2 and 3D 128^3, 256^3. Each update reads
// and writes two float species (16 bytes), so GB/s = 16 x updates/s; the
// fraction of the device's peak is printed for the devices whose peak is
// known (MORPHOFLOW_GPU_PEAK_GBS gives it for any other).
#include <cstdlib>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/bench_setups.h"
#include "bench/bench_suites.h"
#include "bench/bench_timing.h"
#include "core/error.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_explicit_rd.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

namespace {

// Peak memory bandwidth in GB/s of the renderer, 0 when unknown.
double peakBandwidth(const std::string& renderer) {
  if (const char* env = std::getenv("MORPHOFLOW_GPU_PEAK_GBS")) return std::atof(env);
  if (renderer.find("H200") != std::string::npos) return 4800;
  if (renderer.find("H100") != std::string::npos) return renderer.find("PCIe") != std::string::npos ? 2000 : 3350;
  if (renderer.find("A100") != std::string::npos) return 2039;
  return 0;
}

template <int D>
nlohmann::json benchGpuRD(int n, double minSeconds) {
  RDSettings s;
  s.model = "gray-scott";
  s.resolution.assign(D, n);
  s.size.assign(D, double(n));
  s.diffusion = {0.2, 0.1};
  s.integrator = RDIntegrator::ExplicitEuler;
  RDSolver<D> rd(s, *findModel(s.model));
  pearsonStart(&rd);
  const double dt = 0.9 * rd.explicitDiffusionLimit();
  std::vector<float> u(rd.field(0).values().begin(), rd.field(0).values().end());
  std::vector<float> v(rd.field(1).values().begin(), rd.field(1).values().end());
  GpuExplicitRD gpu(s, rd.diffusion(), {rd.parameter(0), rd.parameter(1)}, u, v);
  gpu.step(dt);  // warm-up: the driver's first dispatch
  gpu.finish();
  // Ten steps a sample, so a sample is the GPU's time, not the queue's.
  const std::vector<double> times = timeSteps(minSeconds, [&] {
    for (int k = 0; k < 10; ++k) gpu.step(dt);
    gpu.finish();
  }, [] {});
  const double med = median(times) / 10.0;
  double cells = 1;
  for (int a = 0; a < D; ++a) cells *= n;
  return {{"dim", D}, {"n", n}, {"integrator", "explicit"}, {"backend", "gpu"}, {"dt", dt},
          {"ms_per_step_median", 1e3 * med}, {"cell_updates_per_second", cells / med},
          {"bytes_per_cell_update", 16}, {"gb_per_second", 16.0 * cells / med * 1e-9}};
}

}  // namespace

bool runGpuRDBench(const BenchOptions& o) {
  const GlContext* context = nullptr;
  try {
    context = &GlContext::instance();
  } catch (const GpuUnavailable& e) {
    throw UserError({"--backend", 0, 0}, "", std::string("no usable GPU context: ") + e.what(), "bench on the CPU");
  }
  const GlContext& gl = *context;
  const double peak = peakBandwidth(gl.renderer());
  std::cout << fmt::format("gpu: {}, OpenGL {}; peak bandwidth {}\n", gl.renderer(), gl.version(),
                           peak > 0 ? fmt::format("{:.0f} GB/s", peak) : std::string("unknown (set MORPHOFLOW_GPU_PEAK_GBS)"));
  std::cout << fmt::format("{:>4} {:>6} {:>10} {:>12} {:>14} {:>9} {:>7}\n", "dim", "n", "integrator", "ms/step(med)",
                           "Mcell-updates/s", "GB/s", "of peak");
  nlohmann::json all = nlohmann::json::array();
  for (BenchCase c : selectBenchCases({{2, 256}, {2, 1024}, {2, 4096}, {3, 128}, {3, 256}}, o.size)) {
    nlohmann::json j = c.dim == 2 ? benchGpuRD<2>(c.n, o.minSeconds) : benchGpuRD<3>(c.n, o.minSeconds);
    const double gbs = j["gb_per_second"];
    if (peak > 0) j["fraction_of_peak_bandwidth"] = gbs / peak;
    std::cout << fmt::format("{:>4} {:>6} {:>10} {:>12.3f} {:>14.1f} {:>9.1f} {:>7}\n", c.dim, c.n, "explicit",
                             j["ms_per_step_median"].get<double>(), 1e-6 * j["cell_updates_per_second"].get<double>(), gbs,
                             peak > 0 ? fmt::format("{:.0f}%", 100 * gbs / peak) : std::string("-"))
              << std::flush;
    all.push_back(j);
  }
  if (!o.json.empty()) std::ofstream(o.json) << all.dump(2) << "\n";
  return true;
}

}  // namespace morphoflow
