// `bench rd --backend gpu`: cell updates per second of the explicit
// Gray-Scott step on the GPU (gpu/gpu_explicit_rd.h: single precision) and
// of Kim & Lin's implicit split at ten times that step (gpu/gpu_rd_layer.h:
// double precision, Newton, CG diffusion to 1e-8), the same start and steps
// as the CPU suite; 2D 256^2..4096^2 and 3D 128^3, 256^3. GB/s is the
// traffic model of gpu/gpu_programs.h over the time (the explicit update reads
// and writes two float species, 16 bytes); the fraction of the device's
// peak is printed for the devices whose peak is known
// (MORPHOFLOW_GPU_PEAK_GBS gives it for any other).
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "bench/bench_setups.h"
#include "bench/bench_suites.h"
#include "bench/bench_timing.h"
#include "bench/gpu_bandwidth.h"
#include "core/error.h"
#include "gpu/gpu_counts.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_explicit_rd.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

namespace {

template <int D>
nlohmann::json benchGpuRD(int n, double minSeconds) {
  const RDSettings s = benchGrayScott<D>(n, 1.0, RDIntegrator::ExplicitEuler);
  RDSolver<D> rd(s, *findModel(s.model));
  pearsonStart(&rd);
  const double dt = 0.9 * rd.explicitDiffusionLimit();
  std::vector<float> u(rd.field(0).values().begin(), rd.field(0).values().end());
  std::vector<float> v(rd.field(1).values().begin(), rd.field(1).values().end());
  GpuExplicitRD gpu(s, rd.diffusion(), {rd.parameter(0), rd.parameter(1)}, {}, u, v);
  gpu.step(dt);  // warm-up: the driver's first dispatch
  gpu.finish();
  // Ten steps a sample, so a sample is the GPU's time, not the queue's.
  const GpuCounts counts0 = gpuCounts();
  const std::vector<double> times = timeSteps(minSeconds, [&] {
    for (int k = 0; k < 10; ++k) gpu.step(dt);
    gpu.finish();
  }, [] {});
  const double med = median(times) / 10.0;
  const GpuCounts c = gpuCounts() - counts0;
  double cells = 1;
  for (int a = 0; a < D; ++a) cells *= n;
  return {{"dim", D}, {"n", n}, {"integrator", "explicit"}, {"backend", "gpu"}, {"dt", dt},
          {"ms_per_step_median", 1e3 * med}, {"cell_updates_per_second", cells / med},
          {"bytes_per_cell_update", 16}, {"gb_per_second", 16.0 * cells / med * 1e-9},
          {"dispatches_per_step", double(c.dispatches) / (10.0 * double(times.size()))},
          {"host_waits_per_step", double(c.hostWaits) / (10.0 * double(times.size()))}};
}

template <int D>
nlohmann::json benchGpuKimLin(int n, double minSeconds, GpuPrecision real) {
  RDSolver<D> rd(benchGrayScott<D>(n, 1.0, RDIntegrator::KimLin), *findModel("gray-scott"));
  pearsonStart(&rd);
  const double dt = 10.0 * 0.9 * rd.explicitDiffusionLimit();
  GpuRDLayer<D> gpu(layerUpload(rd), real);
  gpu.step(dt);  // warm-up: the programs, the diffusion systems
  double diffusionIterations = 0;
  const double traffic0 = gpuTrafficBytes();
  const GpuCounts counts0 = gpuCounts();
  const std::vector<double> times = timeSteps(minSeconds, [&] {
    gpu.step(dt);
    gpu.download(0);  // the step's end (its solves already wait on the GPU)
  }, [&] { diffusionIterations += gpu.lastStats().diffusion.iterations; });
  double cells = 1;
  for (int a = 0; a < D; ++a) cells *= n;
  const double med = median(times), bytes = (gpuTrafficBytes() - traffic0) / double(times.size());
  const GpuCounts c = gpuCounts() - counts0;
  return {{"dim", D},
          {"n", n},
          {"integrator", "kim-lin"},
          {"backend", "gpu"},
          {"precision", precisionName(real)},
          {"dt", dt},
          {"ms_per_step_median", 1e3 * med},
          {"cell_updates_per_second", cells / med},
          {"bytes_per_cell_update", bytes / cells},
          {"gb_per_second", bytes / med * 1e-9},
          {"diffusion_iterations_mean", diffusionIterations / double(times.size())},
          {"dispatches_per_step", double(c.dispatches) / double(times.size())},
          {"host_waits_per_step", double(c.hostWaits) / double(times.size())}};
}

}  // namespace

bool runGpuRDBench(const BenchOptions& o) {
  const GpuPrecision real = benchPrecision(o);
  const GpuBandwidth bw = announceGpu(real);
  std::cout << fmt::format("{:>4} {:>6} {:>10} {:>12} {:>14} {:>9} {:>7} {:>7} {:>10} {:>7}\n", "dim", "n",
                           "integrator", "ms/step(med)", "Mcell-updates/s", "GB/s", "of peak", "of copy", "dispatches",
                           "waits");
  nlohmann::json all = nlohmann::json::array();
  for (BenchCase c : selectBenchCases({{2, 256}, {2, 1024}, {2, 4096}, {3, 128}, {3, 256}}, o.size)) {
    for (bool implicit : {false, true}) {
      nlohmann::json j = implicit ? (c.dim == 2 ? benchGpuKimLin<2>(c.n, o.minSeconds, real)
                                                : benchGpuKimLin<3>(c.n, o.minSeconds, real))
                                  : (c.dim == 2 ? benchGpuRD<2>(c.n, o.minSeconds) : benchGpuRD<3>(c.n, o.minSeconds));
      const double gbs = j["gb_per_second"];
      addBandwidthFractions(&j, bw);
      std::cout << fmt::format("{:>4} {:>6} {:>10} {:>12.3f} {:>14.1f} {:>9.1f} {:>7} {:>7} {:>10.1f} {:>7.1f}\n",
                               c.dim, c.n, j["integrator"].get<std::string>(), j["ms_per_step_median"].get<double>(),
                               1e-6 * j["cell_updates_per_second"].get<double>(), gbs, ofPeak(gbs, bw.peak),
                               ofPeak(gbs, bw.copy), j["dispatches_per_step"].get<double>(),
                               j["host_waits_per_step"].get<double>())
                << std::flush;
      all.push_back(j);
    }
  }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

}  // namespace morphoflow
