// `morphoflow run`: loads a scene, steps the fluid, writes frames, probes and
// run.json. Every file is written whole (temporary name, then rename).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/ard_runner.h"
#include "app/frame_writer.h"
#include "app/output_files.h"
#include "app/rd_runner.h"
#include "app/run_options.h"
#include "app/run_clock.h"
#include "app/run_report.h"
#include "core/error.h"
#include "core/parallel.h"
#include "fluid/fluid_solver.h"
#include "fluid/probes.h"
#include "scenes/scene_loader.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

std::string profileCsv(const Profile& p) {
  std::string s = "coord,value\n";
  for (size_t i = 0; i < p.coord.size(); ++i) s += fmt::format("{:.6f},{:.6f}\n", p.coord[i], p.value[i]);
  return s;
}

template <int D>
void initialiseDye(const Scene& scene, FluidSolver<D>* f) {
  if (scene.dye.initial == "none") return;
  const int n = scene.dye.stripes;
  Grid<float, D>& dye = f->dye();
  const IVec<D>& cells = f->cells();
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    int bx = int(std::floor(double(k[0]) / cells[0] * n));
    int by = int(std::floor(double(k[1]) / cells[1] * n));
    bool on = scene.dye.initial == "stripes" ? bx % 2 == 0 : (bx + by) % 2 == 0;
    dye[i] = on && !f->solid()[i] ? 1.0f : 0.0f;
  });
}

template <int D>
Grid<float, D> outputField(const std::string& name, const FluidSolver<D>& f) {
  if (name == "speed") return speedField(f);
  if (name == "dye") return f.dye();
  if (name == "pressure") return f.pressure();
  return vorticityField(f);
}

template <int D>
int run(const Scene& scene, const RunOptions& opt) {
  const fs::path out(opt.out);
  fs::create_directories(out);

  FluidSolver<D> fluid(scene.fluid);
  initialiseDye<D>(scene, &fluid);
  // With a duration and adaptive dt the step count is not known up front:
  // run until the end time (stepsEstimate is then only for progress).
  const RunClock clock(scene.time);
  const long stepsEstimate = scene.totalSteps();
  const auto wall0 = std::chrono::steady_clock::now();

  std::array<double, FluidStepStats::kStages> stageTotals{};
  long pressureIterations = 0, viscosityIterations = 0;
  int maxPressureIterations = 0, unconverged = 0;
  double maxPressureResidual = 0;
  std::vector<double> forceTime, drag, lift;
  std::string forcesCsv = "step,time,drag_coefficient,lift_coefficient\n";
  const ProbeSettings& pr = scene.probes;
  const double q = 0.5 * scene.fluid.density * pr.referenceSpeed * pr.referenceSpeed * pr.referenceArea;
  int flowAxis = 0;
  for (int a = 0; a < D; ++a)
    for (bool hi : {false, true})
      if (scene.fluid.boundaries.side(a, hi).kind == BoundaryKind::Inflow) flowAxis = a;
  const int liftAxis = flowAxis == 1 ? 0 : 1;
  FrameWriter frames(out, scene.output, opt);
  auto writeFrame = [&](long step) {
    long frame = frames.frameAt(step);
    if (frame < 0) return;
    frames.write<D>(frame, outputField<D>(scene.output.field, fluid), scene.output.field == "vorticity" && D == 2);
    if (scene.output.fields) {
      static const std::vector<std::string> names = {"speed", "vorticity", "pressure", "dye"};
      std::vector<Grid<float, D>> all;
      for (const std::string& n : names) all.push_back(outputField<D>(n, fluid));
      frames.writeFields<D>(frame, names, all, fluid.time(), step);
    }
  };

  writeFrame(0);
  long step = 0;
  for (; clock.running(step, fluid.time()); ++step) {
    if (opt.lastFrame >= 0 && step >= long(opt.lastFrame + 1) * scene.output.every) break;
    fluid.step(clock.dt(fluid));
    const FluidStepStats& st = fluid.lastStats();
    for (int k = 0; k < FluidStepStats::kStages; ++k) stageTotals[size_t(k)] += st.seconds[size_t(k)];
    pressureIterations += st.pressure.iterations;
    viscosityIterations += st.viscosity.iterations;
    maxPressureIterations = std::max(maxPressureIterations, st.pressure.iterations);
    maxPressureResidual = std::max(maxPressureResidual, st.pressure.residual);
    if (!st.pressure.converged) {
      if (unconverged++ == 0 && !opt.quiet)
        std::cerr << fmt::format("warning: step {}: pressure solve stopped at relative residual {:.2e} after {} iterations\n",
                                 step + 1, st.pressure.residual, st.pressure.iterations);
    }
    double speed = fluid.maxSpeed();
    if (!std::isfinite(speed))
      throw std::runtime_error(fmt::format("the simulation diverged at step {} (non-finite velocity)", step + 1));
    if (pr.forces) {
      auto F = obstacleForce<D>(fluid);
      double cd = F[size_t(flowAxis)] / q, cl = F[size_t(liftAxis)] / q;
      forceTime.push_back(fluid.time());
      drag.push_back(cd);
      lift.push_back(cl);
      forcesCsv += fmt::format("{},{:.6f},{:.6f},{:.6f}\n", step + 1, fluid.time(), cd, cl);
    }
    writeFrame(step + 1);
    if (!opt.quiet && (step + 1) % std::max<long>(1, stepsEstimate / 20) == 0)
      std::cerr << fmt::format("\rstep {}/~{}  t = {:.4f}  |u|max = {:.3f}  pressure its = {}   ", step + 1, stepsEstimate,
                               fluid.time(), speed, st.pressure.iterations)
                << std::flush;
  }
  const double wall = finishRun(scene, opt, &frames, wall0);
  nlohmann::json j = runReport(scene, opt,
                               {{"dimension", D},
                                {"resolution", scene.fluid.resolution},
                                {"size", scene.fluid.size},
                                {"cell_size", fluid.h()},
                                {"viscosity", scene.fluid.viscosity},
                                {"reynolds", scene.reynolds},
                                {"reference_length", pr.referenceLength},
                                {"reference_speed", pr.referenceSpeed},
                                {"dt", scene.time.dt},
                                {"cfl", scene.time.cfl}},
                               step, fluid.time(), frames, wall);
  nlohmann::json stages;
  for (int k = 0; k < FluidStepStats::kStages; ++k)
    stages[FluidStepStats::kStageNames[k]] = {{"total_seconds", stageTotals[size_t(k)]},
                                              {"ms_per_step", step ? 1e3 * stageTotals[size_t(k)] / double(step) : 0.0}};
  j["stages"] = stages;
  j["solvers"] = {{"pressure_iterations_mean", step ? double(pressureIterations) / double(step) : 0.0},
                  {"pressure_iterations_max", maxPressureIterations},
                  {"pressure_residual_max", maxPressureResidual},
                  {"pressure_unconverged_steps", unconverged},
                  {"viscosity_iterations_mean", step ? double(viscosityIterations) / double(step) : 0.0}};

  if (pr.centerlines) {
    fs::create_directories(out / "profiles");
    // Vertical centreline: u along y; horizontal centreline: v along x.
    writeTextFile(out / "profiles" / "u_vertical_centerline.csv",
                  profileCsv(centerlineProfile<D>(fluid, 0, 1, pr.referenceSpeed)));
    writeTextFile(out / "profiles" / "v_horizontal_centerline.csv",
                  profileCsv(centerlineProfile<D>(fluid, 1, 0, pr.referenceSpeed)));
  }
  if (pr.forces) {
    writeTextFile(out / "forces.csv", forcesCsv);
    double start = pr.strouhalStart >= 0 ? pr.strouhalStart : 0.5 * fluid.time();
    StrouhalEstimate st = estimateStrouhal(forceTime, lift, start, pr.referenceLength, pr.referenceSpeed);
    double cdMean = 0;
    int n = 0;
    for (size_t i = 0; i < drag.size(); ++i)
      if (forceTime[i] >= start) {
        cdMean += drag[i];
        ++n;
      }
    j["strouhal"] = st.periods > 0 ? nlohmann::json(st.strouhal) : nlohmann::json(nullptr);
    j["lift"] = {{"periods", st.periods},
                 {"period_spread", st.periodSpread},
                 {"period_strouhal", st.periodStrouhal},
                 {"measured_from_time", start}};
    j["drag_coefficient_mean"] = n ? cdMean / n : 0.0;
  }
  writeTextFile(out / "run.json", j.dump(2) + "\n");
  if (!opt.quiet)
    std::cerr << fmt::format("done: {} steps, t = {:.4f}, {:.2f} s wall, {} frames -> {}\n", step, fluid.time(), wall,
                             frames.written(), out.string());
  return 0;
}

}  // namespace

int runScene(const RunOptions& opt) {
  Scene scene = loadScene(opt.scene, opt.overrides);
  if (opt.backend == "gpu")
    throw UserError({"--backend", 0, 0}, "", "the gpu backend is not part of this build yet", "use --backend tbb or serial");
  int threads = opt.backend == "serial" ? 1 : opt.threads;
  ThreadLimit limit(threads);
  if (!scene.hasFluid) return runReactionDiffusion(scene, opt);
  if (scene.rd.enabled) return runCoupled(scene, opt);
  return scene.dimension == 2 ? run<2>(scene, opt) : run<3>(scene, opt);
}

}  // namespace morphoflow
