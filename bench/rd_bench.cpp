// Suite `rd`: cell updates per second of a reaction-diffusion step, Gray-Scott
// (Pearson, F = 0.04, k = 0.06, unit cells) by explicit Euler at 0.9 of its
// diffusion limit (RDSolver's doubles, and the fused float step of
// rd/fused_explicit.h) and by Kim & Lin's implicit split (Newton reaction, MGPCG
// diffusion to 1e-8) at 10 times that step; 2D 256^2..2048^2 and 3D 128^3,
// 1 and 2 threads.
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
#include "core/parallel.h"
#include "rd/fused_explicit.h"
#include "rd/generalized_diffusion.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

namespace {

template <int D>
nlohmann::json benchRD(int n, bool implicit, int threads, double minSeconds) {
  ThreadLimit limit(threads);
  RDSolver<D> rd(benchGrayScott<D>(n, 1.0, implicit ? RDIntegrator::KimLin : RDIntegrator::ExplicitEuler),
                 *findModel("gray-scott"));
  pearsonStart(&rd);
  const double dt = 0.9 * rd.explicitDiffusionLimit() * (implicit ? 10.0 : 1.0);
  rd.step(dt);  // warm-up: allocations, multigrid setup
  double newtonIt = 0, diffIt = 0;
  const std::vector<double> times = timeSteps(minSeconds, [&] { rd.step(dt); }, [&] {
    newtonIt = std::max(newtonIt, double(rd.lastStats().newton.maxIterations));
    diffIt += rd.lastStats().diffusion.iterations;
  });
  const double med = median(times);
  double cells = 1;
  for (int a = 0; a < D; ++a) cells *= n;
  return {{"dim", D},
          {"n", n},
          {"integrator", implicit ? "kim-lin" : "explicit"},
          {"threads", threads},
          {"dt", dt},
          {"steps", times.size()},
          {"ms_per_step_median", 1e3 * med},
          {"cell_updates_per_second", cells / med},
          // the explicit step: two double species read and written; Kim & Lin's from its solves' steps
          {"bytes_per_cell_update", implicit ? kimLinStepBytes(1.0, 2, diffIt / double(times.size())) : 32.0},
          {"newton_iterations_max", newtonIt},
          {"diffusion_iterations_mean", diffIt / double(times.size())}};
}

// The fused float step (rd/fused_explicit.h) on the same start and dt, timed
// over passes of its automatic steps per pass; where that is several
// (temporal blocking), a second row times the same step one step a pass,
// its passes interleaved with the first's (the host's slow stretches then
// fall on both).
template <int D>
nlohmann::json benchFused(int n, int threads, double minSeconds, bool kernel5) {
  ThreadLimit limit(threads);
  const RDSettings st = benchGrayScott<D>(n, 1.0, RDIntegrator::ExplicitEuler);
  RDSolver<D> rd(st, *findModel("gray-scott"));
  pearsonStart(&rd);
  const double dt = 0.9 * rd.explicitDiffusionLimit();
  auto engine = [&](bool single) {
    auto e = FusedExplicitRD<D>::create("gray-scott", rd.cells(), 1.0, true, st.diffusion, {});
    // Seed 000's 5 x 5 kernel: Table 2 (d) on cells of 2.2 (docs/models.md), the same d per cell.
    if constexpr (D == 2)
      if (kernel5) e->setKernel(GeneralizedDiffusion(*kramersMoyalPreset("d"), n, n, 2.2).kernel(), {});
    if (single) e->setTemporalBlocking(1, 0);
    for (int s = 0; s < 2; ++s)
      for (size_t i = 0; i < rd.field(s).size(); ++i) e->field(s)[i] = float(rd.field(s)[i]);
    return e;
  };
  std::vector<std::unique_ptr<FusedExplicitRD<D>>> engines;
  engines.push_back(engine(false));
  const int k = engines[0]->stepsPerPass();
  if (k > 1) engines.push_back(engine(true));
  for (auto& e : engines) e->step(dt, k);  // warm-up
  std::vector<std::vector<double>> times(engines.size());
  timeSteps(minSeconds * double(engines.size()), [&] {
    for (size_t v = 0; v < engines.size(); ++v) times[v].push_back(timeOnce([&] { engines[v]->step(dt, k); }) / k);
  }, [] {});
  nlohmann::json rows = nlohmann::json::array();
  for (size_t v = 0; v < engines.size(); ++v) {
    const double med = median(times[v]);
    const int perPass = engines[v]->stepsPerPass();
    rows.push_back({{"dim", D},
                    {"n", n},
                    {"integrator", std::string(kernel5 ? "fused-5x5" : "fused") + (v == 1 ? "-1" : "")},
                    {"threads", threads},
                    {"dt", dt},
                    {"steps", times[v].size() * size_t(k)},
                    {"steps_per_pass", perPass},
                    {"ms_per_step_median", 1e3 * med},
                    {"cell_updates_per_second", cellCount(rd.cells()) / med},
                    {"bytes_per_cell_update", 16.0 / perPass},  // two float species read and written once a pass
                    {"newton_iterations_max", 0},
                    {"diffusion_iterations_mean", 0}});
  }
  return rows;
}

}  // namespace

bool runRDBench(const BenchOptions& o) {
  const std::vector<BenchCase> cases =
      selectBenchCases({{2, 256}, {2, 512}, {2, 1024}, {2, 2048}, {3, 128}, {3, 256}}, o.size);
  nlohmann::json all = nlohmann::json::array();
  const std::array<double, 3> triad = suiteTriads(o.minSeconds);
  std::cout << fmt::format("{:>4} {:>6} {:>11} {:>7} {:>12} {:>14} {:>9} {:>9} {:>9}\n", "dim", "n", "integrator",
                           "threads", "ms/step(med)", "Mcell-updates/s", "newton", "pcg-its", "of triad");
  auto report = [&](nlohmann::json j) {
    const double triadNow = triad[size_t(j["threads"].get<int>())];
    j["triad_gb_per_second"] = triadNow;
    j["of_triad"] =
        j["cell_updates_per_second"].get<double>() * j["bytes_per_cell_update"].get<double>() / 1e9 / triadNow;
    std::cout << fmt::format("{:>4} {:>6} {:>11} {:>7} {:>12.2f} {:>14.2f} {:>9.0f} {:>9.1f} {:>9.2f}\n",
                             j["dim"].get<int>(), j["n"].get<int>(), j["integrator"].get<std::string>(),
                             j["threads"].get<int>(), j["ms_per_step_median"].get<double>(),
                             1e-6 * j["cell_updates_per_second"].get<double>(),
                             j["newton_iterations_max"].get<double>(), j["diffusion_iterations_mean"].get<double>(),
                             j["of_triad"].get<double>())
              << std::flush;
    all.push_back(j);
  };
  // explicit (double), fused (float), fused 5 x 5 (2D), Kim & Lin (256^3:
  // the fused rows only); a fused case gives two rows where it blocks.
  enum Kind { kExplicit, kFused, k5x5, kKimLin };
  for (BenchCase c : cases)
    for (Kind kind : {kExplicit, kFused, k5x5, kKimLin})
      for (int threads : {1, 2}) {
        const bool fused = kind == kFused || kind == k5x5;
        if ((kind == k5x5 && c.dim != 2) || (c.dim == 3 && c.n > 128 && !fused)) continue;
        if (!fused) report(c.dim == 2 ? benchRD<2>(c.n, kind == kKimLin, threads, o.minSeconds)
                                      : benchRD<3>(c.n, kind == kKimLin, threads, o.minSeconds));
        else
          for (const nlohmann::json& j : c.dim == 2 ? benchFused<2>(c.n, threads, o.minSeconds, kind == k5x5)
                                                    : benchFused<3>(c.n, threads, o.minSeconds, false))
            report(j);
      }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

}  // namespace morphoflow
