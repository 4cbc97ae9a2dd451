// Suite `coupling`: seed 001's Table 1 on this machine. Steps per second of
// the fluid alone (the `fluid` suite's cavity: Re = 100, MacCormack, MGPCG
// to 1e-6, CFL 1) and of the fluid carrying a Gray-Scott ARD layer on the
// same grid (Kim & Lin's implicit reaction and MGPCG diffusion at ten times
// the explicit diffusion limit, then linear semi-Lagrangian advection), with
// the serial and tbb schedulers, on 1 and on 2 threads (the trace: the
// 2-thread runs); the overhead ratio is (fluid + ARD time) / (fluid-only
// time) per step, from medians; the fluid-only and tbb steps' compulsory
// traffic as a fraction of the triad's bandwidth (bench/step_traffic.h).
#include <fstream>
#include <iostream>
#include <optional>
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
#include "core/stage_trace.h"
#include "coupling/cpu_coupled_stepper.h"
#include "coupling/coupling_choices.h"
#include "rd/model_registry.h"

namespace morphoflow {

namespace {

constexpr int kWarmup = 3;

struct CoupledTiming {
  double step, fluid, ard;
  double bytes;  // mean compulsory bytes a step
};

template <int D>
CoupledTiming fluidOnly(int n, double minSeconds) {
  FluidSolver<D> f(benchCavity<D>(n));
  const double dt = f.h();
  for (int i = 0; i < kWarmup; ++i) f.step(dt);
  double bytes = 0.0;
  const std::vector<double> t = timeSteps(minSeconds, [&] { f.step(dt); }, [&] {
    bytes += fluidStepBytes<D>(cellCount<D>(f.cells()), f.lastStats());
  });
  return {median(t), median(t), 0.0, bytes / double(t.size())};
}

template <int D>
CoupledTiming fluidWithARD(int n, Backend backend, ChemicalInterpolation interpolation, double minSeconds,
                           StageTrace* trace) {
  FluidSolver<D> f(benchCavity<D>(n));
  // on the fluid's grid, diffusion rates 0.2 h^2 and 0.1 h^2 (the `rd` suite's, per cell)
  RDSolver<D> rd(benchGrayScott<D>(n, 1.0 / n, RDIntegrator::KimLin), *findModel("gray-scott"));
  pearsonStart(&rd);
  const double dt = f.h();
  const double rdScale = 10.0 * 0.9 * rd.explicitDiffusionLimit() / dt;
  ChemicalDomain<D> domain;
  domain.cells = rd.cells();
  domain.h = rd.h();
  ARDSolver<D> ard(&rd, ChemicalAdvector<D>(domain, interpolation), CouplingMode::ARD, rdScale);
  CpuCoupledStepper<D> stepper(&f, &ard, backend);
  for (int i = 0; i < kWarmup; ++i) stepper.step(dt);
  if (trace)
    trace->beginGroup(fmt::format("{} {}^{}", backend == Backend::TBB ? "tbb" : "serial", n, D));
  stepper.setTrace(trace);
  std::vector<double> fluid, ardT;
  double bytes = 0.0;
  const std::vector<double> times = timeSteps(minSeconds, [&] { stepper.step(dt); }, [&] {
    fluid.push_back(stepper.fluidSeconds());
    ardT.push_back(stepper.ardSeconds());
    bytes += fluidStepBytes<D>(cellCount<D>(f.cells()), f.lastStats()) +
             ardStepBytes(D, cellCount<D>(rd.cells()), rd.species(), rd.lastStats().diffusion.iterations);
  });
  return {median(times), median(fluid), median(ardT), bytes / double(times.size())};
}

template <int D>
nlohmann::json benchCase(int n, int threads, ChemicalInterpolation interpolation, double minSeconds, StageTrace* trace,
                         double triad) {
  ThreadLimit limit(threads);
  const CoupledTiming fluid = fluidOnly<D>(n, minSeconds);
  const double alone = fluid.step;
  nlohmann::json j = {{"dim", D}, {"n", n}, {"threads", threads}, {"fluid_only_ms", 1e3 * alone},
                      {"fluid_only_steps_per_second", 1.0 / alone}, {"triad_gb_per_second", triad},
                      {"interpolation", interpolationName(interpolation)},
                      {"fluid_only_of_triad", fluid.bytes / alone / 1e9 / triad}};
  for (Backend b : {Backend::Serial, Backend::TBB}) {
    const CoupledTiming t = fluidWithARD<D>(n, b, interpolation, minSeconds, trace);
    const std::string k = b == Backend::TBB ? "tbb" : "serial";
    j[k] = {{"ms", 1e3 * t.step},
            {"steps_per_second", 1.0 / t.step},
            {"fluid_part_ms", 1e3 * t.fluid},
            {"ard_part_ms", 1e3 * t.ard},
            {"overhead", t.step / alone},
            {"of_triad", t.bytes / t.step / 1e9 / triad}};
  }
  return j;
}

}  // namespace

bool runCouplingBench(const BenchOptions& o) {
  const std::vector<BenchCase> cases =
      selectBenchCases({{2, 128}, {2, 256}, {2, 512}, {2, 1024}, {3, 64}, {3, 128}}, o.size);
  std::optional<StageTrace> trace;
  if (!o.trace.empty()) trace.emplace();
  nlohmann::json all = nlohmann::json::array();
  const ChemicalInterpolation interpolation = interpolationNamed(o.interpolation);
  std::cout << "overhead = (fluid + ARD) / fluid only, target <= 1.10 at 512^2 and above (2 threads); chemicals: "
            << o.interpolation << " interpolation\n";
  const std::array<double, 3> triad = suiteTriads(o.minSeconds);
  std::cout << fmt::format("{:>4} {:>6} {:>4} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>9} {:>9}\n", "dim", "n", "thr",
                           "fluid/s", "serial/s", "tbb/s", "ms tbb", "ovh ser", "ovh tbb", "bw fluid", "bw tbb");
  for (BenchCase c : cases)
    for (int threads : {1, 2}) {
      StageTrace* t = trace && threads == 2 ? &*trace : nullptr;
      nlohmann::json j = c.dim == 2
                             ? benchCase<2>(c.n, threads, interpolation, o.minSeconds, t, triad[size_t(threads)])
                             : benchCase<3>(c.n, threads, interpolation, o.minSeconds, t, triad[size_t(threads)]);
      std::cout
          << fmt::format(
                 "{:>4} {:>6} {:>4} {:>10.2f} {:>10.2f} {:>10.2f} {:>10.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f}\n",
                 c.dim, c.n, threads, j["fluid_only_steps_per_second"].get<double>(),
                 j["serial"]["steps_per_second"].get<double>(), j["tbb"]["steps_per_second"].get<double>(),
                 j["tbb"]["ms"].get<double>(), j["serial"]["overhead"].get<double>(),
                 j["tbb"]["overhead"].get<double>(), j["fluid_only_of_triad"].get<double>(),
                 j["tbb"]["of_triad"].get<double>())
          << std::flush;
      all.push_back(j);
    }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  if (trace) {
    writeFileAtomically(o.trace, trace->chromeJson());
    std::cout << fmt::format("trace: {} stages -> {} (open in ui.perfetto.dev or chrome://tracing)\n",
                             trace->events().size(), o.trace);
  }
  return true;
}

}  // namespace morphoflow
