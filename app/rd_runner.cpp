// Steps an RDSolver from the scene's initial state and writes colormapped
// frames of one species plus run.json (solver statistics).
#include "app/rd_runner.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/frame_writer.h"
#include "app/output_files.h"
#include "app/version.h"
#include "core/parallel.h"
#include "core/random.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// Standard normal deviate from two uniforms (Box-Muller), reproducible per index.
double gaussian(uint64_t seed, uint64_t stream, uint64_t i) {
  double u1 = std::max(uniform01(seed, 2 * stream, i), 1e-300), u2 = uniform01(seed, 2 * stream + 1, i);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

template <int D>
void initialise(const Scene& scene, RDSolver<D>* rd) {
  const RDInitial& I = scene.rd.initial;
  const IVec<D> n = rd->cells();
  const uint64_t seed = scene.seed;
  for (int s = 0; s < rd->species(); ++s) {
    Grid<double, D>& g = rd->field(s);
    forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
      double v = I.values[size_t(s)];
      if (I.randomRange) v = I.range[0] + (I.range[1] - I.range[0]) * uniform01(seed, 100 + uint64_t(s), i);
      if (I.square > 0) {
        bool inside = true;
        for (int a = 0; a < D; ++a) inside &= std::abs((k[a] + 0.5) / n[a] - 0.5) < 0.5 * I.square;
        if (inside) v = I.squareValues[size_t(s)];
      }
      v += I.noise[size_t(s)] * (2.0 * uniform01(seed, uint64_t(s), i) - 1.0);
      g[i] = v;
    });
  }
  // Gaussian perturbation of parameters by a percentage (seed 004 sec. 3.1).
  for (auto [k, percent] : scene.rd.perturb) {
    std::vector<double> f(rd->field(0).size());
    const double base = rd->parameter(k);
    for (size_t i = 0; i < f.size(); ++i) f[i] = base * (1.0 + 0.01 * percent * gaussian(seed, 200 + uint64_t(k), i));
    rd->setParameterField(k, std::move(f));
  }
}

template <int D>
int run(const Scene& scene, const RunOptions& opt) {
  const ReactionModel& model = *findModel(scene.rd.settings.model);
  RDSolver<D> rd(scene.rd.settings, model);
  initialise<D>(scene, &rd);
  const fs::path out(opt.out);
  fs::create_directories(out);
  FrameWriter frames(out, scene.output, opt);
  const std::vector<std::string>& names = model.info().species;
  const int shown = int(std::find(names.begin(), names.end(), scene.output.field) - names.begin());
  const long steps = scene.totalSteps();
  auto checkFinite = [&](long step) {
    for (int s = 0; s < rd.species(); ++s)
      for (double v : rd.field(s).values())
        if (!std::isfinite(v))
          throw std::runtime_error(fmt::format("the simulation diverged at step {} (species {} is not finite); "
                                               "use the kim-lin integrator or a smaller time.dt",
                                               step, names[size_t(s)]));
  };
  auto writeFrame = [&](long step) {
    long frame = frames.frameAt(step);
    if (frame < 0) return;
    checkFinite(step);
    const Grid<double, D>& src = rd.field(shown);
    Grid<float, D> f(src.dims());
    for (size_t i = 0; i < f.size(); ++i) f[i] = float(src[i]);
    frames.write<D>(frame, f, false);
  };
  const auto wall0 = std::chrono::steady_clock::now();
  NewtonStats newton;
  long diffusionIterations = 0;
  int diffusionMax = 0, unconverged = 0;
  writeFrame(0);
  long step = 0;
  for (; step < steps; ++step) {
    if (opt.lastFrame >= 0 && step >= long(opt.lastFrame + 1) * scene.output.every) break;
    rd.step(scene.time.dt);
    const RDStepStats& st = rd.lastStats();
    newton.merge(st.newton);
    diffusionIterations += st.diffusion.iterations;
    diffusionMax = std::max(diffusionMax, st.diffusion.iterations);
    unconverged += st.diffusion.converged ? 0 : 1;
    writeFrame(step + 1);
    if (!opt.quiet && (step + 1) % std::max<long>(1, steps / 20) == 0)
      std::cerr << fmt::format("\rstep {}/{}  t = {:.4g}", step + 1, steps, rd.time()) << std::flush;
  }
  checkFinite(step);
  if (!opt.quiet) std::cerr << "\n";
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  nlohmann::json j;
  j["version"] = kVersion;
  j["scene_file"] = scene.path;
  j["scene"] = nlohmann::json::parse(scene.resolvedJson);
  j["overrides"] = opt.overrides;
  j["resolved"] = {{"dimension", D},
                   {"model", model.info().name},
                   {"species", names},
                   {"resolution", scene.rd.settings.resolution},
                   {"size", scene.rd.settings.size},
                   {"cell_size", rd.h()},
                   {"diffusion", rd.diffusion()},
                   {"dt", scene.time.dt},
                   {"explicit_diffusion_limit", rd.explicitDiffusionLimit()}};
  j["backend"] = opt.backend;
  j["threads"] = opt.threads > 0 ? opt.threads : hardwareThreads();
  j["steps"] = step;
  j["time"] = rd.time();
  j["frames_written"] = frames.written();
  j["wall_seconds"] = wall;
  j["solvers"] = {{"newton_cells", newton.cells},
                  {"newton_failures", newton.failures},
                  {"newton_iterations_max", newton.maxIterations},
                  {"newton_residual_max", newton.maxResidual},
                  {"diffusion_iterations_mean", step ? double(diffusionIterations) / double(step) : 0.0},
                  {"diffusion_iterations_max", diffusionMax},
                  {"diffusion_unconverged_steps", unconverged}};
  writeTextFile(out / "run.json", j.dump(2) + "\n");
  if (!opt.quiet)
    std::cerr << fmt::format("done: {} steps, t = {:.4g}, {:.2f} s wall, {} frames -> {}\n", step, rd.time(), wall,
                             frames.written(), out.string());
  return 0;
}

}  // namespace

int runReactionDiffusion(const Scene& scene, const RunOptions& opt) {
  return scene.dimension == 2 ? run<2>(scene, opt) : run<3>(scene, opt);
}

}  // namespace morphoflow
