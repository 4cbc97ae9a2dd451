// Steps a fluid and its ARD layer with the serial or tbb-overlap scheduler
// (coupling/coupled_stepper.h), writes frames of a species or a fluid field,
// float dumps of every species, and run.json with the time each side took.
#include "app/ard_runner.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/frame_writer.h"
#include "app/output_files.h"
#include "app/rd_runner.h"
#include "app/run_clock.h"
#include "app/run_report.h"
#include "core/parallel.h"
#include "coupling/coupled_stepper.h"
#include "fluid/probes.h"
#include "rd/model_registry.h"
#include "render/colormap.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// The advection domain of the RD grid: the fluid's walls, inflow sides and
// obstacles (sampled at RD cell centres).
template <int D>
ChemicalDomain<D> chemicalDomain(const Scene& scene, const FluidSolver<D>& fluid, const RDSolver<D>& rd) {
  ChemicalDomain<D> d;
  d.cells = rd.cells();
  d.h = rd.h();
  d.periodic = fluid.constraints().periodic();
  for (int a = 0; a < D; ++a)
    for (int hi = 0; hi < 2; ++hi)
      d.inflow[size_t(a)][size_t(hi)] = scene.fluid.boundaries.side(a, hi != 0).kind == BoundaryKind::Inflow;
  d.inflowValues = scene.coupling.inflowValues;
  d.solidValues = scene.coupling.solidValues;
  const Grid<uint8_t, D>& solid = fluid.solid();
  bool any = false;
  std::vector<uint8_t> mask(rd.field(0).size(), 0);
  forEachCell<D>(d.cells, [&](const IVec<D>& k, size_t i) {
    IVec<D> f;
    for (int a = 0; a < D; ++a)
      f[a] = std::clamp(int(std::floor((k[a] + 0.5) * d.h / fluid.h())), 0, fluid.cells()[a] - 1);
    mask[i] = solid(f);
  });
  for (uint8_t m : mask) any |= m != 0;
  if (any) d.solid = std::move(mask);
  return d;
}

template <int D>
int run(const Scene& scene, const RunOptions& opt) {
  const ReactionModel& model = *findModel(scene.rd.settings.model);
  FluidSolver<D> fluid(scene.fluid);
  RDSolver<D> rd(scene.rd.settings, model);
  initialState<D>(scene, &rd);
  applyScene<D>(scene, &rd);
  const CouplingScene& C = scene.coupling;
  const CouplingMode mode = C.mode == "passive" ? CouplingMode::Passive
                            : C.mode == "rd-only" ? CouplingMode::RDOnly
                                                  : CouplingMode::ARD;
  ARDSolver<D> ard(&rd,
                   ChemicalAdvector<D>(chemicalDomain<D>(scene, fluid, rd),
                                       C.interpolation == "cubic" ? ChemicalInterpolation::Cubic : ChemicalInterpolation::Linear),
                   mode, C.rdTimeScale);
  CoupledStepper<D> stepper(&fluid, &ard, opt.backend == "serial" ? CouplingBackend::Serial : CouplingBackend::TBB);

  const fs::path out(opt.out);
  fs::create_directories(out);
  FrameWriter frames(out, scene.output, opt);
  const std::vector<std::string>& names = model.info().species;
  const auto shownIt = std::find(names.begin(), names.end(), scene.output.field);
  const bool showSpecies = shownIt != names.end();
  const bool twoSpecies = scene.output.colormap == kTwoSpeciesPalette;
  auto writeFrame = [&](long step) {
    long frame = frames.frameAt(step);
    if (frame < 0) return;
    checkFinite(rd, fmt::format("at step {}", step));
    if (twoSpecies) {
      const Grid<float, D> green = toFloat<D>(rd.field(1));
      frames.write<D>(frame, toFloat<D>(rd.field(0)), false, &green);
    } else if (showSpecies) {
      frames.write<D>(frame, toFloat<D>(rd.field(int(shownIt - names.begin()))), false);
    } else {
      const std::string& f = scene.output.field;
      frames.write<D>(frame, f == "speed" ? speedField(fluid) : f == "dye" ? fluid.dye() : f == "pressure" ? fluid.pressure()
                                                                                                        : vorticityField(fluid),
                      f == "vorticity" && D == 2);
    }
    if (scene.output.fields) {
      std::vector<Grid<float, D>> all;
      for (int s = 0; s < rd.species(); ++s) all.push_back(toFloat<D>(rd.field(s)));
      frames.writeFields<D>(frame, names, all, fluid.time(), step);
    }
  };

  // With a duration and adaptive dt the step count is not known up front:
  // run until the end time (stepsEstimate is then only for progress).
  const RunClock clock(scene.time);
  const long stepsEstimate = scene.totalSteps();
  const auto wall0 = std::chrono::steady_clock::now();
  double fluidSeconds = 0, ardSeconds = 0, stepSeconds = 0;
  long pressureIterations = 0, diffusionIterations = 0;
  int unconverged = 0;
  writeFrame(0);
  long step = 0;
  for (; clock.running(step, fluid.time()); ++step) {
    if (opt.lastFrame >= 0 && step >= long(opt.lastFrame + 1) * scene.output.every) break;
    stepper.step(clock.dt(fluid));
    fluidSeconds += stepper.fluidSeconds();
    ardSeconds += stepper.ardSeconds();
    stepSeconds += stepper.stepSeconds();
    pressureIterations += fluid.lastStats().pressure.iterations;
    diffusionIterations += rd.lastStats().diffusion.iterations;
    unconverged += fluid.lastStats().pressure.converged ? 0 : 1;
    if (!std::isfinite(fluid.maxSpeed()))
      throw std::runtime_error(fmt::format("the simulation diverged at step {} (non-finite velocity)", step + 1));
    writeFrame(step + 1);
    if (!opt.quiet && (step + 1) % std::max<long>(1, stepsEstimate / 20) == 0)
      std::cerr << fmt::format("\rstep {}/~{}  t = {:.4f}  |u|max = {:.3f}", step + 1, stepsEstimate, fluid.time(),
                               fluid.maxSpeed())
                << std::flush;
  }
  checkFinite(rd, fmt::format("at step {}", step));
  const double wall = finishRun(scene, opt, &frames, wall0);
  nlohmann::json j = runReport(scene, opt,
                               {{"dimension", D},
                                {"resolution", scene.fluid.resolution},
                                {"size", scene.fluid.size},
                                {"reynolds", scene.reynolds},
                                {"model", model.info().name},
                                {"species", names},
                                {"rd_resolution", scene.rd.settings.resolution},
                                {"rd_cell_size", rd.h()},
                                {"diffusion", rd.diffusion()},
                                {"coupling_mode", C.mode},
                                {"interpolation", C.interpolation},
                                {"rd_time_scale", C.rdTimeScale},
                                {"dt", scene.time.dt},
                                {"cfl", scene.time.cfl}},
                               step, fluid.time(), frames, wall);
  j["coupling"] = {{"fluid_seconds", fluidSeconds},
                   {"ard_seconds", ardSeconds},
                   {"step_seconds", stepSeconds},
                   {"overlapped", opt.backend != "serial"}};
  j["solvers"] = {{"pressure_iterations_mean", step ? double(pressureIterations) / double(step) : 0.0},
                  {"pressure_unconverged_steps", unconverged},
                  {"diffusion_iterations_mean", step ? double(diffusionIterations) / double(step) : 0.0}};
  writeTextFile(out / "run.json", j.dump(2) + "\n");
  if (!opt.quiet)
    std::cerr << fmt::format("done: {} steps, t = {:.4f}, {:.2f} s wall (fluid {:.2f} s, ARD {:.2f} s), {} frames -> {}\n",
                             step, fluid.time(), wall, fluidSeconds, ardSeconds, frames.written(), out.string());
  return 0;
}

}  // namespace

int runCoupled(const Scene& scene, const RunOptions& opt) {
  return scene.dimension == 2 ? run<2>(scene, opt) : run<3>(scene, opt);
}

}  // namespace morphoflow
