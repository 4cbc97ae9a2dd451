// `bench fluid --backend gpu` and `bench coupling --backend gpu`: the CPU
// suites' problems on the GPU. fluid: ms per step of the lid-driven cavity
// (Re = 100, MacCormack, MGPCG to 1e-6, CFL 1) and per stage, solver
// iterations; coupling: steps per second of the fluid alone and carrying a
// Gray-Scott ARD layer on its grid (Kim & Lin at ten times the explicit
// diffusion limit, linear advection), and the overhead (fluid + ARD) / fluid
// (seed 001 Table 1). Both print GB/s, the traffic model of
// gpu/gpu_programs.h over the time, and its fractions of the device's peak and
// of its measured copy bandwidth.
#include <fstream>
#include <iostream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "bench/bench_setups.h"
#include "bench/bench_suites.h"
#include "bench/bench_timing.h"
#include "bench/gpu_bandwidth.h"
#include "coupling/coupling_choices.h"
#include "gpu/gpu_ard_solver.h"
#include "fluid/fluid_solver.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/model_registry.h"

namespace morphoflow {

namespace {

constexpr int kWarmup = 3;  // the coupling suite's steps before the timed ones

// The cases of both suites: the CPU's sizes and the GPU targets' (1024^2, 256^3).
const std::vector<BenchCase> kCases = {{2, 256}, {2, 512}, {2, 1024}, {2, 2048}, {3, 64}, {3, 128}, {3, 256}};

struct Timed {
  double seconds;  // median per step
  double bytes;    // traffic per step
  double dispatches, hostWaits;  // per step (gpu/gpu_counts.h)
};

// Median step time and mean traffic of `step` (which ends with the GPU idle: its solves wait on it).
template <typename Step, typename After>
Timed timeGpu(double minSeconds, Step&& step, After&& after) {
  const double traffic0 = gpuTrafficBytes();
  const GpuCounts counts0 = gpuCounts();
  const std::vector<double> times = timeSteps(minSeconds, step, after);
  const double n = double(times.size());
  const GpuCounts c = gpuCounts() - counts0;
  return {median(times), (gpuTrafficBytes() - traffic0) / n, double(c.dispatches) / n, double(c.hostWaits) / n};
}

template <int D>
nlohmann::json benchGpuFluid(int n, double minSeconds, GpuPrecision real, BenchContent content = BenchContent::Plain,
                             int warmUpSteps = BenchOptions{}.warmUpSteps) {
  FluidSolver<D> host(benchCavityWith<D>(n, content));  // the constraints; never stepped
  GpuFluid<D> gpu(host.settings(), host.constraints(), real);
  const double dt = host.h();
  for (int i = 0; i < warmUpSteps; ++i) gpu.step(dt);
  double pit = 0, vit = 0;
  std::array<double, FluidStepStats::kStages> stage{};
  bool converged = true;
  int steps = 0;
  const Timed t = timeGpu(minSeconds, [&] { gpu.step(dt); }, [&] {
    const FluidStepStats& st = gpu.lastStats();
    pit += st.pressure.iterations;
    vit += st.viscosity.iterations;
    converged = converged && st.pressure.converged;
    for (int k = 0; k < FluidStepStats::kStages; ++k) stage[size_t(k)] += st.seconds[size_t(k)];
    ++steps;
  });
  nlohmann::json j = {{"dim", D},
                      {"n", n},
                      {"backend", "gpu"},
                      {"content", contentName(content)},
                      {"precision", precisionName(real)},
                      {"warm_up_steps", warmUpSteps},
                      {"steps", steps},
                      {"ms_per_step_median", 1e3 * t.seconds},
                      {"steps_per_second", 1.0 / t.seconds},
                      {"pressure_iterations_mean", pit / steps},
                      {"viscosity_iterations_mean", vit / steps},
                      {"pressure_converged", converged},
                      {"gb_per_second", t.bytes / t.seconds * 1e-9},
                      {"dispatches_per_step", t.dispatches},
                      {"host_waits_per_step", t.hostWaits}};
  for (int k = 0; k < FluidStepStats::kStages; ++k)
    j["ms_" + std::string(FluidStepStats::kStageNames[k])] = 1e3 * stage[size_t(k)] / steps;
  return j;
}

template <int D>
nlohmann::json benchGpuCoupling(int n, ChemicalInterpolation interpolation, double minSeconds, GpuPrecision real) {
  const nlohmann::json fluid = benchGpuFluid<D>(n, minSeconds, real);
  FluidSolver<D> host(benchCavity<D>(n));
  RDSolver<D> rd(benchGrayScott<D>(n, 1.0 / n, RDIntegrator::KimLin), *findModel("gray-scott"));
  pearsonStart(&rd);
  const double dt = host.h();
  const double rdScale = 10.0 * 0.9 * rd.explicitDiffusionLimit() / dt;
  ChemicalDomain<D> domain;
  domain.cells = rd.cells();
  domain.h = rd.h();
  GpuFluid<D> gf(host.settings(), host.constraints(), real);
  GpuRDLayer<D> layer(layerUpload(rd), real);
  GpuARDSolver<D> ard(&layer, domain, interpolation, CouplingMode::ARD, rdScale, host.cells(), host.h());
  auto step = [&] {
    gf.step(dt);  // then the chemicals through the velocity it advected through
    ard.step(dt, gf);
  };
  for (int i = 0; i < kWarmup; ++i) step();
  std::vector<double> ardSeconds;
  const Timed t =
      timeGpu(minSeconds, step, [&] { ardSeconds.push_back(ard.stageSeconds()[0] + ard.stageSeconds()[1]); });
  const double alone = 1e-3 * fluid["ms_per_step_median"].get<double>();
  nlohmann::json j = {{"dim", D},
                      {"n", n},
                      {"backend", "gpu"},
                      {"precision", precisionName(real)},
                      {"fluid_only_ms", 1e3 * alone},
                      {"fluid_only_steps_per_second", 1.0 / alone},
                      {"ms", 1e3 * t.seconds},
                      {"steps_per_second", 1.0 / t.seconds},
                      {"ard_part_ms", 1e3 * median(ardSeconds)},
                      {"interpolation", interpolationName(interpolation)},
                      {"overhead", t.seconds / alone},
                      {"gb_per_second", t.bytes / t.seconds * 1e-9},
                      {"dispatches_per_step", t.dispatches},
                      {"host_waits_per_step", t.hostWaits}};
  return j;
}

}  // namespace

bool runGpuFluidBench(const BenchOptions& o) {
  const GpuPrecision real = benchPrecision(o);
  const GpuBandwidth bw = announceGpu(real);
  std::cout << fmt::format(
      "{:>4} {:>6} {:>12} {:>12} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8} {:>7} {:>7} {:>10} {:>7}\n", "dim", "n",
      "content", "ms/step(med)", "p-iters", "v-iters", "forces", "advect", "diffuse", "project", "GB/s", "of peak",
      "of copy", "dispatches", "waits");
  nlohmann::json all = nlohmann::json::array();
  // As the CPU's suite (without its smoke): 3D and 2D 512^2 again with a body at rest and moving (its
  // placement and the host's rebuild of the systems in the step's time), each right after the plain case.
  for (const auto& [c, content] : fluidBenchRuns(selectBenchCases(kCases, o.size), false)) {
    nlohmann::json j = c.dim == 2 ? benchGpuFluid<2>(c.n, o.minSeconds, real, content, o.warmUpSteps)
                                  : benchGpuFluid<3>(c.n, o.minSeconds, real, content, o.warmUpSteps);
    addBandwidthFractions(&j, bw);
    std::cout << fmt::format(
                     "{:>4} {:>6} {:>12} {:>12.3f} {:>8.1f} {:>8.1f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>8.1f} "
                     "{:>7} {:>7} {:>10.1f} {:>7.1f}{}\n",
                     c.dim, c.n, contentName(content), j["ms_per_step_median"].get<double>(),
                     j["pressure_iterations_mean"].get<double>(), j["viscosity_iterations_mean"].get<double>(),
                     j["ms_forces"].get<double>(), j["ms_advect"].get<double>(), j["ms_diffuse"].get<double>(),
                     j["ms_project"].get<double>(), j["gb_per_second"].get<double>(),
                     ofPeak(j["gb_per_second"].get<double>(), bw.peak),
                     ofPeak(j["gb_per_second"].get<double>(), bw.copy), j["dispatches_per_step"].get<double>(),
                     j["host_waits_per_step"].get<double>(),
                     j["pressure_converged"].get<bool>() ? "" : "  (unconverged)")
              << std::flush;
    all.push_back(j);
  }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

bool runGpuCouplingBench(const BenchOptions& o) {
  const GpuPrecision real = benchPrecision(o);
  const GpuBandwidth bw = announceGpu(real);
  const ChemicalInterpolation interpolation = interpolationNamed(o.interpolation);
  std::cout
      << "overhead = (fluid + ARD) / fluid only; targets: >= 1000 steps/s at 1024^2, >= 30 at 256^3, overhead <= 1.10; "
         "chemicals: "
      << o.interpolation << " interpolation\n";
  std::cout << fmt::format("{:>4} {:>6} {:>10} {:>10} {:>10} {:>10} {:>9} {:>8} {:>7} {:>7} {:>10} {:>7}\n", "dim", "n",
                           "fluid/s", "gpu/s", "ms gpu", "ms ARD", "overhead", "GB/s", "of peak", "of copy",
                           "dispatches", "waits");
  nlohmann::json all = nlohmann::json::array();
  for (BenchCase c : selectBenchCases(kCases, o.size)) {
    nlohmann::json j = c.dim == 2 ? benchGpuCoupling<2>(c.n, interpolation, o.minSeconds, real)
                                  : benchGpuCoupling<3>(c.n, interpolation, o.minSeconds, real);
    addBandwidthFractions(&j, bw);
    std::cout << fmt::format(
                     "{:>4} {:>6} {:>10.1f} {:>10.1f} {:>10.3f} {:>10.3f} {:>9.2f} {:>8.1f} {:>7} {:>7} {:>10.1f} "
                     "{:>7.1f}\n",
                     c.dim, c.n, j["fluid_only_steps_per_second"].get<double>(), j["steps_per_second"].get<double>(),
                     j["ms"].get<double>(), j["ard_part_ms"].get<double>(), j["overhead"].get<double>(),
                     j["gb_per_second"].get<double>(), ofPeak(j["gb_per_second"].get<double>(), bw.peak),
                     ofPeak(j["gb_per_second"].get<double>(), bw.copy), j["dispatches_per_step"].get<double>(),
                     j["host_waits_per_step"].get<double>())
              << std::flush;
    all.push_back(j);
  }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

}  // namespace morphoflow
