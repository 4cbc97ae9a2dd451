// Steps an RDSolver from the scene's initial state and writes colormapped
// frames of one species plus run.json (solver statistics).
#include "app/rd_runner.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/frame_writer.h"
#include "app/output_files.h"
#include "app/run_report.h"
#include "core/parallel.h"
#include "core/spatial_field.h"
#include "core/random.h"
#include "rd/coarse_to_fine.h"
#include "rd/model_registry.h"
#include "render/colormap.h"
#include "rd/rd_solver.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// Standard normal deviate from two uniforms (Box-Muller), reproducible per index.
double gaussian(uint64_t seed, uint64_t stream, uint64_t i) {
  double u1 = std::max(uniform01(seed, 2 * stream, i), 1e-300), u2 = uniform01(seed, 2 * stream + 1, i);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

// The scene's initial species values.
template <int D>
void initialState(const Scene& scene, RDSolver<D>* rd) {
  const RDInitial& I = scene.rd.initial;
  const IVec<D> n = rd->cells();
  const uint64_t seed = scene.seed;
  std::vector<std::vector<double>> maps(size_t(rd->species()));
  for (const auto& [s, f] : scene.rd.initialMaps) maps[size_t(s)] = sampleSpatialField<D>(f.field, n);
  for (int s = 0; s < rd->species(); ++s) {
    Grid<double, D>& g = rd->field(s);
    const std::vector<double>& map = maps[size_t(s)];
    forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
      double v = I.values[size_t(s)];
      if (I.randomRange) v = I.range[0] + (I.range[1] - I.range[0]) * uniform01(seed, 100 + uint64_t(s), i);
      if (I.square > 0) {
        bool inside = true;
        for (int a = 0; a < D; ++a) inside &= std::abs((k[a] + 0.5) / n[a] - 0.5) < 0.5 * I.square;
        if (inside) v = I.squareValues[size_t(s)];
      }
      if (!map.empty()) v = map[i];
      v += I.noise[size_t(s)] * (2.0 * uniform01(seed, uint64_t(s), i) - 1.0);
      g[i] = v;
    });
  }
}

// The scene's parameter maps, perturbations and fixed regions, sampled on rd's grid.
template <int D>
void applyScene(const Scene& scene, RDSolver<D>* rd) {
  const IVec<D> n = rd->cells();
  const uint64_t seed = scene.seed;
  // Parameter maps, then a Gaussian perturbation by a percentage on top (seed 004 sec. 3.1).
  const size_t cells = rd->field(0).size();
  std::vector<std::vector<double>> params(rd->model().info().parameters.size());
  for (const auto& [k, f] : scene.rd.parameterMaps) params[size_t(k)] = sampleSpatialField<D>(f.field, n);
  for (auto [k, percent] : scene.rd.perturb) {
    std::vector<double>& f = params[size_t(k)];
    if (f.empty()) f.assign(cells, rd->parameter(k));
    for (size_t i = 0; i < cells; ++i) f[i] *= 1.0 + 0.01 * percent * gaussian(seed, 200 + uint64_t(k), i);
  }
  for (size_t k = 0; k < params.size(); ++k)
    if (!params[k].empty()) rd->setParameterField(int(k), std::move(params[k]));
  // Inhomogeneous anisotropic diffusion (seed 004 eq. 11-19).
  if (const RDAnisotropy& an = scene.rd.anisotropy; an.enabled) {
    DiffusionTensorSpec<D> spec;
    spec.lambda1 = sampleSpatialField<D>(an.lambda1.field, n);
    spec.lambda2 = sampleSpatialField<D>(an.lambda2.field, n);
    if (an.direction.empty()) {  // a = (cos theta, sin theta, 0)   (eq. 12)
      const std::vector<double> theta = sampleSpatialField<D>(an.theta.field, n);
      for (int a = 0; a < D; ++a) spec.direction[size_t(a)].assign(cells, 0.0);
      for (size_t i = 0; i < cells; ++i) {
        spec.direction[0][i] = std::cos(theta[i]);
        spec.direction[1][i] = std::sin(theta[i]);
      }
    } else {
      for (int a = 0; a < D; ++a) spec.direction[size_t(a)] = sampleSpatialField<D>(an.direction[size_t(a)].field, n);
    }
    spec.species = an.species;
    spec.shape = an.shape;
    spec.shapeSpecies = an.shapeSpecies;
    rd->setDiffusionTensor(std::move(spec));
  }
  // Kim & Lin's cosine lobes (seed 001 eq. 14-17).
  if (const RDCosineLobes& lb = scene.rd.lobes; lb.enabled) {
    CosineLobeSpec spec;
    spec.speeds = lb.speeds;
    spec.witkinKass = lb.witkinKass;
    spec.theta0 = sampleSpatialField<D>(lb.theta0.field, n);
    spec.species = lb.species;
    rd->setCosineLobes(std::move(spec));
  }
  // Fixed regions: held at their values from the start (seed 004 fig. 20).
  if (!scene.rd.fixed.empty()) {
    const size_t ns = size_t(rd->species());
    std::vector<std::vector<uint8_t>> mask(ns);
    std::vector<std::vector<double>> values(ns);
    for (const RDFixedRegion& fr : scene.rd.fixed) {
      const std::vector<double> inside = sampleSpatialField<D>(fr.where.field, n);
      for (size_t q = 0; q < fr.species.size(); ++q) {
        const size_t s = size_t(fr.species[q]);
        if (mask[s].empty()) mask[s].assign(cells, 0), values[s].assign(cells, 0.0);
        for (size_t i = 0; i < cells; ++i)
          if (inside[i] != 0.0) {
            mask[s][i] = 1;
            values[s][i] = fr.values[q];
            rd->field(int(s))[i] = fr.values[q];
          }
      }
    }
    rd->setFixedCells(std::move(mask), std::move(values));
  }
}

template <int D>
void checkFinite(const RDSolver<D>& rd, const std::string& where) {
  for (int s = 0; s < rd.species(); ++s)
    for (double v : rd.field(s).values())
      if (!std::isfinite(v))
        throw std::runtime_error(fmt::format("the simulation diverged {} (species {} is not finite); "
                                             "use the kim-lin integrator or a smaller time.dt",
                                             where, rd.model().info().species[size_t(s)]));
}

template void initialState<2>(const Scene&, RDSolver<2>*);
template void initialState<3>(const Scene&, RDSolver<3>*);
template void applyScene<2>(const Scene&, RDSolver<2>*);
template void applyScene<3>(const Scene&, RDSolver<3>*);
template void checkFinite<2>(const RDSolver<2>&, const std::string&);
template void checkFinite<3>(const RDSolver<3>&, const std::string&);

namespace {

// Every species of `coarse` prolongated onto `fine` (twice the cells per axis).
template <int D>
void prolongateState(const RDSolver<D>& coarse, RDSolver<D>* fine) {
  for (int s = 0; s < fine->species(); ++s)
    prolongate<D>(coarse.field(s), &fine->field(s), fine->settings().boundary == RDBoundary::Periodic);
}

// Coarse-to-fine acceleration (seed 002, seed 000 sec. 6): grows the pattern on
// grids 2^L, ..., 2 times coarser over the same domain, each started from the
// previous one prolongated; returns the last (2 times coarser) grid, or null.
template <int D>
std::unique_ptr<RDSolver<D>> growCoarse(const Scene& scene, const ReactionModel& model, bool quiet,
                                        nlohmann::json* report) {
  std::unique_ptr<RDSolver<D>> prev;
  for (int level = scene.rd.coarseLevels; level >= 1; --level) {
    RDSettings st = scene.rd.settings;
    for (int& r : st.resolution) r >>= level;
    auto cur = std::make_unique<RDSolver<D>>(st, model);
    if (prev) prolongateState<D>(*prev, cur.get());
    else initialState<D>(scene, cur.get());
    applyScene<D>(scene, cur.get());
    const auto t0 = std::chrono::steady_clock::now();
    const double dt = scene.time.dt * (scene.rd.coarseScaleDt ? std::pow(4.0, level) : 1.0);
    for (long k = 0; k < scene.rd.coarseSteps; ++k) cur->step(dt);
    checkFinite(*cur, fmt::format("on the coarse grid {}", fmt::join(st.resolution, "x")));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!quiet)
      std::cerr << fmt::format("coarse grid {}: {} steps, {:.2f} s\n", fmt::join(st.resolution, "x"),
                               scene.rd.coarseSteps, wall);
    report->push_back({{"resolution", st.resolution}, {"steps", scene.rd.coarseSteps}, {"dt", dt}, {"time", cur->time()},
                       {"wall_seconds", wall}});
    prev = std::move(cur);
  }
  return prev;
}

template <int D>
int run(const Scene& scene, const RunOptions& opt) {
  const ReactionModel& model = *findModel(scene.rd.settings.model);
  nlohmann::json coarseReport = nlohmann::json::array();
  std::unique_ptr<RDSolver<D>> coarse = growCoarse<D>(scene, model, opt.quiet, &coarseReport);
  RDSolver<D> rd(scene.rd.settings, model);
  if (coarse) prolongateState<D>(*coarse, &rd);
  else initialState<D>(scene, &rd);
  coarse.reset();
  applyScene<D>(scene, &rd);
  const fs::path out(opt.out);
  fs::create_directories(out);
  FrameWriter frames(out, scene.output, opt);
  const std::vector<std::string>& names = model.info().species;
  const int shown = int(std::find(names.begin(), names.end(), scene.output.field) - names.begin());
  const long steps = scene.totalSteps();
  const bool twoSpecies = scene.output.colormap == kTwoSpeciesPalette;
  auto asFloat = [&](int s) { return toFloat<D>(rd.field(s)); };
  auto writeFrame = [&](long step) {
    long frame = frames.frameAt(step);
    if (frame < 0) return;
    checkFinite(rd, fmt::format("at step {}", step));
    if (twoSpecies) {
      const Grid<float, D> green = asFloat(1);
      frames.write<D>(frame, asFloat(0), false, &green);
    } else {
      frames.write<D>(frame, asFloat(shown), false);
    }
    if (scene.output.fields) {
      std::vector<Grid<float, D>> all;
      for (int s = 0; s < rd.species(); ++s) all.push_back(asFloat(s));
      frames.writeFields<D>(frame, names, all, rd.time(), step);
    }
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
  checkFinite(rd, fmt::format("at step {}", step));
  const double wall = finishRun(scene, opt, &frames, wall0);
  nlohmann::json j = runReport(scene, opt,
                               {{"dimension", D},
                                {"model", model.info().name},
                                {"species", names},
                                {"resolution", scene.rd.settings.resolution},
                                {"size", scene.rd.settings.size},
                                {"cell_size", rd.h()},
                                {"diffusion", rd.diffusion()},
                                {"dt", scene.time.dt},
                                {"explicit_diffusion_limit", rd.explicitDiffusionLimit()}},
                               step, rd.time(), frames, wall);
  j["coarse_to_fine"] = coarseReport;
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
