// Suite `fluid`: ms per stable-fluids step (lid-driven cavity, Re = 100,
// MacCormack advection, MGPCG pressure to 1e-6) in 2D and 3D, 1 and 2
// threads, and the fraction of the triad's bandwidth the step's compulsory
// traffic reaches (bench/step_traffic.h).
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "bench/bench_setups.h"
#include "bench/bench_suites.h"
#include "bench/bench_timing.h"
#include "bench/step_traffic.h"
#include "core/error.h"
#include "core/parallel.h"
#include "fluid/fluid_solver.h"

namespace morphoflow {

namespace {

// The cavity with smoke (a hot source, buoyancy, vorticity confinement,
// cooling and dissipation): what the smoke stages add to the step.
template <int D>
FluidSettings benchSmokyCavity(int n) {
  FluidSettings s = benchCavity<D>(n);
  SmokeSettings& m = s.smoke;
  m.enabled = true;
  m.heat = 1.0;
  m.weight = 0.1;
  m.vorticity = 1.0;
  m.cooling = 0.2;
  m.dissipation = 0.05;
  SmokeSource src;
  src.region.shape = ObstacleShape::Sphere;
  src.region.center = {0.5, 0.2, 0.5};
  src.region.radius = 0.1;
  src.density = 2.0;
  src.temperature = 4.0;
  m.sources = {src};
  return s;
}

template <int D>
FluidSettings benchSettings(int n, BenchContent content) {
  if (content == BenchContent::Smoke) return benchSmokyCavity<D>(n);
  return benchCavityWith<D>(n, content);
}

template <int D>
nlohmann::json benchFluid(int n, int threads, const BenchOptions& o, double triad, BenchContent content) {
  ThreadLimit limit(threads);
  const bool smoke = content == BenchContent::Smoke;
  FluidSolver<D> f(benchSettings<D>(n, content));
  const double dt = f.h();  // CFL 1 at the lid speed
  for (int i = 0; i < o.warmUpSteps; ++i) f.step(dt);  // warm-up: the flow starts to develop
  std::vector<double> pit, vit;
  std::array<double, FluidStepStats::kStages> stage{};
  bool converged = true;
  const double cells = cellCount<D>(f.cells());
  double bytes = 0.0;
  const std::vector<double> times = timeSteps(
      o.minSeconds, [&] { f.step(dt); },
      [&] {
        pit.push_back(f.lastStats().pressure.iterations);
        vit.push_back(f.lastStats().viscosity.iterations);
        converged &= f.lastStats().pressure.converged;
        bytes += fluidStepBytes<D>(cells, f.lastStats());
        for (int k = 0; k < FluidStepStats::kStages; ++k) stage[size_t(k)] += f.lastStats().seconds[size_t(k)];
      });
  double meanIt = 0, meanVit = 0;
  for (double p : pit) meanIt += p;
  for (double v : vit) meanVit += v;
  meanIt /= double(pit.size());
  meanVit /= double(vit.size());
  nlohmann::json j = {{"dim", D},
                      {"n", n},
                      {"smoke", smoke},
                      {"content", contentName(content)},
                      {"threads", threads},
                      {"warm_up_steps", o.warmUpSteps},
                      {"steps", times.size()},
                      {"ms_per_step_median", 1e3 * median(times)},
                      {"pressure_iterations_mean", meanIt},
                      {"viscosity_iterations_mean", meanVit},
                      {"pressure_converged", converged}};
  const double gbs = bytes / double(times.size()) / median(times) / 1e9;
  j["compulsory_gb_per_second"] = gbs;
  j["triad_gb_per_second"] = triad;
  j["of_triad"] = gbs / triad;
  for (int k = 0; k < FluidStepStats::kStages; ++k)
    j["ms_" + std::string(FluidStepStats::kStageNames[k])] = 1e3 * stage[size_t(k)] / double(times.size());
  return j;
}

// The body moving against the body at rest, their steps taken in turn
// (one of each, and so on): on a shared host the load drifts over seconds,
// and two cases timed one after the other see different loads, where a
// pair of steps sees the same. The median of the pairs' ratios.
template <int D>
nlohmann::json benchMovingOverRest(int n, int threads, const BenchOptions& o) {
  ThreadLimit limit(threads);
  FluidSolver<D> rest(benchSettings<D>(n, BenchContent::BodyAtRest));
  FluidSolver<D> moving(benchSettings<D>(n, BenchContent::BodyMoving));
  const double dt = rest.h();
  for (int i = 0; i < o.warmUpSteps; ++i) rest.step(dt), moving.step(dt);
  std::vector<double> atRest, ratio;
  const std::vector<double> pairs = timeSteps(
      2.0 * o.minSeconds,
      [&] {
        atRest.push_back(timeOnce([&] { rest.step(dt); }));
        ratio.push_back(timeOnce([&] { moving.step(dt); }) / atRest.back());
      },
      [] {});
  return {{"dim", D},
          {"n", n},
          {"content", "moving over rest"},
          {"threads", threads},
          {"warm_up_steps", o.warmUpSteps},
          {"steps", pairs.size()},
          {"ms_at_rest_median", 1e3 * median(atRest)},
          {"moving_over_rest_median", median(ratio)}};
}

}  // namespace

bool runFluidBench(const BenchOptions& o) {
  const std::vector<BenchCase> cases =
      selectBenchCases({{2, 128}, {2, 256}, {2, 512}, {2, 1024}, {3, 64}, {3, 128}}, o.size);
  nlohmann::json all = nlohmann::json::array();
  const std::array<double, 3> triad = suiteTriads(o.minSeconds);
  std::cout << fmt::format("{:>4} {:>6} {:>12} {:>7} {:>12} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "dim", "n",
                           "content", "threads", "ms/step(med)", "p-iters", "v-iters", "forces", "advect", "diffuse",
                           "project", "of triad");
  // 3D cases run again with smoke (sources, temperature, buoyancy,
  // confinement), and 3D and 2D 512^2 with a body at rest and moving, each
  // right after the plain one.
  for (const auto& [c, content] : fluidBenchRuns(cases, true)) {
    for (int threads : {1, 2}) {
      nlohmann::json j = c.dim == 2 ? benchFluid<2>(c.n, threads, o, triad[size_t(threads)], content)
                                    : benchFluid<3>(c.n, threads, o, triad[size_t(threads)], content);
      std::cout << fmt::format(
                       "{:>4} {:>6} {:>12} {:>7} {:>12.2f} {:>8.1f} {:>8.1f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f} "
                       "{:>9.2f}{}\n",
                       c.dim, c.n, contentName(content), threads, j["ms_per_step_median"].get<double>(),
                       j["pressure_iterations_mean"].get<double>(), j["viscosity_iterations_mean"].get<double>(),
                       j["ms_forces"].get<double>(), j["ms_advect"].get<double>(), j["ms_diffuse"].get<double>(),
                       j["ms_project"].get<double>(), j["of_triad"].get<double>(),
                       j["pressure_converged"].get<bool>() ? "" : "  (unconverged)")
                << std::flush;
      all.push_back(j);
    }
    if (content != BenchContent::BodyMoving) continue;
    for (int threads : {1, 2}) {
      nlohmann::json j = c.dim == 2 ? benchMovingOverRest<2>(c.n, threads, o) : benchMovingOverRest<3>(c.n, threads, o);
      std::cout << fmt::format(
                       "{:>4} {:>6} {:>12} {:>7}   moving adds {:+.1f}% to the step at rest (median of {} pairs "
                       "of steps taken in turn)\n",
                       c.dim, c.n, "pair", threads, 100.0 * (j["moving_over_rest_median"].get<double>() - 1.0),
                       j["steps"].get<size_t>())
                << std::flush;
      all.push_back(j);
    }
  }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

bool runRDBench(const BenchOptions& o);        // rd_bench.cpp
bool runCouplingBench(const BenchOptions& o);  // coupling_bench.cpp
bool runGpuRDBench(const BenchOptions& o);     // gpu_rd_bench.cpp
bool runGpuFluidBench(const BenchOptions& o);  // gpu_fluid_bench.cpp
bool runGpuCouplingBench(const BenchOptions& o);
bool runRooflineBench(const BenchOptions& o);  // roofline_bench.cpp

bool runBenchSuite(const std::string& suite, const BenchOptions& o) {
  if (o.backend == "gpu") {
    if (suite == "rd") return runGpuRDBench(o);
    if (suite == "fluid") return runGpuFluidBench(o);
    if (suite == "coupling") return runGpuCouplingBench(o);
    return false;
  }
  if (suite == "fluid") return runFluidBench(o);
  if (suite == "rd") return runRDBench(o);
  if (suite == "coupling") return runCouplingBench(o);
  if (suite == "roofline") return runRooflineBench(o);
  return false;
}

const char* benchSuiteNames() { return "fluid, rd, coupling, roofline"; }

}  // namespace morphoflow
