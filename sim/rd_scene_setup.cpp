#include "sim/rd_scene_setup.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/parallel.h"
#include "sim/simulation.h"
#include "core/spatial_field.h"
#include "core/random.h"
#include "rd/brush_strokes.h"
#include "rd/coarse_to_fine.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

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

// Parameter maps, then a Gaussian perturbation by a percentage on top (seed 004 sec. 3.1).
template <int D>
void applyParameterFields(const Scene& scene, RDSolver<D>* rd) {
  const size_t cells = rd->field(0).size();
  std::vector<std::vector<double>> params(rd->model().info().parameters.size());
  for (const auto& [k, f] : scene.rd.parameterMaps) params[size_t(k)] = sampleSpatialField<D>(f.field, rd->cells());
  for (auto [k, percent] : scene.rd.perturb) {
    std::vector<double>& f = params[size_t(k)];
    if (f.empty()) f.assign(cells, rd->parameter(k));
    for (size_t i = 0; i < cells; ++i) f[i] *= 1.0 + 0.01 * percent * gaussian(scene.seed, 200 + uint64_t(k), i);
  }
  for (size_t k = 0; k < params.size(); ++k)
    if (!params[k].empty()) rd->setParameterField(int(k), std::move(params[k]));
}

// Brush strokes, their direction extended to every cell (Kim & Lin sec. 6).
// Each stroke must cover a cell; the direction is painted only where it
// steers something (empty otherwise).
template <int D>
PaintedStrokes<D> paintSceneStrokes(const Scene& scene, const RDSolver<D>& rd) {
  const bool periodic = rd.settings().boundary == RDBoundary::Periodic;
  for (const RDStroke& s : scene.rd.strokes) {
    try {
      strokeCoverage<D>(s.stroke, rd.cells(), rd.settings().size, periodic);
    } catch (const std::invalid_argument&) {
      throw UserError(s.where, s.key, "the stroke covers no cell of the grid",
                      s.stroke.isImage()
                          ? "an image stroke covers the cells brighter than its range's middle: this image has none"
                          : "give points inside the domain, or a wider stroke");
    }
  }
  const bool steers = (scene.rd.anisotropy.enabled && scene.rd.anisotropy.thetaFromStrokes) ||
                      (scene.rd.lobes.enabled && scene.rd.lobes.theta0FromStrokes);
  if (!steers) return {};
  std::vector<BrushStroke> strokes;
  for (const RDStroke& s : scene.rd.strokes) strokes.push_back(s.stroke);
  try {
    return paintStrokes<D>(strokes, rd.cells(), rd.settings().size, periodic);
  } catch (const std::invalid_argument&) {  // every stroke an image without edges
    const RDStroke& first = scene.rd.strokes.front();
    throw UserError(first.where, first.key,
                    "the strokes give no direction: an image stroke's direction comes from its edges, "
                    "and these images are uniform where they cover",
                    "add a polyline stroke, use an image with edges, or give the direction another way");
  }
}

// Inhomogeneous anisotropic diffusion (seed 004 eq. 11-19).
template <int D>
void applyAnisotropy(const RDAnisotropy& an, const PaintedStrokes<D>& painted, RDSolver<D>* rd) {
  const IVec<D> n = rd->cells();
  const size_t cells = rd->field(0).size();
  DiffusionTensorSpec<D> spec;
  spec.lambda1 = sampleSpatialField<D>(an.lambda1.field, n);
  spec.lambda2 = sampleSpatialField<D>(an.lambda2.field, n);
  if (an.directionFromVelocity) {  // isotropic until the run sets a = u / |u| (GivenFlowSimulation)
    for (int a = 0; a < D; ++a) spec.direction[size_t(a)].assign(cells, 0.0);
  } else if (an.direction.empty()) {  // a = (cos theta, sin theta, 0)   (eq. 12)
    std::vector<double> theta = an.thetaFromStrokes ? painted.angle : sampleSpatialField<D>(an.theta.field, n);
    if (an.thetaFromStrokes)
      for (double& t : theta) t += an.strokeAngle;
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
template <int D>
void applyCosineLobes(const RDCosineLobes& lb, const PaintedStrokes<D>& painted, RDSolver<D>* rd) {
  CosineLobeSpec spec;
  spec.speeds = lb.speeds;
  spec.witkinKass = lb.witkinKass;
  if (lb.theta0FromStrokes) {  // lobe 1 (centred at phi = theta + theta0 = 0) along the stroke, turned by strokeAngle
    spec.theta0.resize(rd->field(0).size());
    for (size_t i = 0; i < spec.theta0.size(); ++i) spec.theta0[i] = -(painted.angle[i] + lb.strokeAngle);
  } else {
    spec.theta0 = sampleSpatialField<D>(lb.theta0.field, rd->cells());
  }
  spec.species = lb.species;
  rd->setCosineLobes(std::move(spec));
}

// Fixed regions and the chemical strokes' deposit: held at their values from
// the start (seed 004 fig. 20, seed 001 fig. 3).
template <int D>
void applyFixedCells(const Scene& scene, RDSolver<D>* rd) {
  if (scene.rd.fixed.empty() && !scene.rd.strokesDeposit()) return;
  const IVec<D> n = rd->cells();
  const size_t cells = rd->field(0).size();
  const size_t ns = size_t(rd->species());
  std::vector<std::vector<uint8_t>> mask(ns);
  std::vector<std::vector<double>> values(ns);
  auto hold = [&](const std::vector<int>& species, const std::vector<double>& held, auto&& inside) {
    for (size_t q = 0; q < species.size(); ++q) {
      const size_t s = size_t(species[q]);
      if (mask[s].empty()) mask[s].assign(cells, 0), values[s].assign(cells, 0.0);
      for (size_t i = 0; i < cells; ++i)
        if (inside(i)) {
          mask[s][i] = 1;
          values[s][i] = held[q];
          rd->field(int(s))[i] = held[q];
        }
    }
  };
  for (const RDFixedRegion& fr : scene.rd.fixed) {
    const std::vector<double> inside = sampleSpatialField<D>(fr.where.field, n);
    hold(fr.species, fr.values, [&](size_t i) { return inside[i] != 0.0; });
  }
  const bool periodic = rd->settings().boundary == RDBoundary::Periodic;
  for (const RDStroke& s : scene.rd.strokes) {
    if (s.species.empty()) continue;
    const std::vector<uint8_t> under = strokeCoverage<D>(s.stroke, n, rd->settings().size, periodic);
    hold(s.species, s.values, [&](size_t i) { return under[i] != 0; });
  }
  rd->setFixedCells(std::move(mask), std::move(values));
}

// The scene's parameter maps, perturbations, anisotropy and fixed regions, sampled on rd's grid.
template <int D>
void applyScene(const Scene& scene, RDSolver<D>* rd) {
  applyParameterFields(scene, rd);
  const PaintedStrokes<D> painted = paintSceneStrokes(scene, *rd);
  if (scene.rd.anisotropy.enabled) applyAnisotropy(scene.rd.anisotropy, painted, rd);
  if (scene.rd.lobes.enabled) applyCosineLobes(scene.rd.lobes, painted, rd);
  // McGraw's generalized diffusion (seed 000), one 5 x 5 operator on this grid.
  if (const RDGeneralized& g = scene.rd.generalized; g.enabled) {
    if constexpr (D == 2)
      rd->setGeneralizedDiffusion(
          std::make_shared<const GeneralizedDiffusion>(g.tensors, rd->cells()[0], rd->cells()[1], rd->h(),
                                                       g.savitzkyGolaySecond ? SecondDerivatives::SavitzkyGolay
                                                                             : SecondDerivatives::CentralDifferences),
          g.species);
  }
  applyFixedCells(scene, rd);
}

std::string rdStage(const RDSettings& s) {
  switch (s.integrator) {
    case RDIntegrator::ExplicitEuler: return "the explicit reaction-diffusion step";
    case RDIntegrator::SemiImplicit: return "the semi-implicit reaction-diffusion step";
    default: return "the reaction (Kim & Lin's Newton) and implicit diffusion step";
  }
}

template <int D>
void checkFinite(const RDSolver<D>& rd, const std::string& where, const std::string& stage) {
  for (int s = 0; s < rd.species(); ++s)
    for (double v : rd.field(s).values())
      if (!(std::abs(v) <= double(std::numeric_limits<float>::max()))) {  // NaN, infinite, or not a float when stored
        const bool isExplicit = rd.settings().integrator == RDIntegrator::ExplicitEuler;
        throw NonFiniteError(
            fmt::format("the simulation diverged {} in {}: species {} is {} (it must fit a float to be stored)", where,
                        stage, rd.model().info().species[size_t(s)], std::isnan(v) ? "NaN" : fmt::format("{:g}", v)),
            isExplicit
                ? fmt::format("the explicit integrator's limit for this diffusion is time.dt = {:.4g}, and a stiff "
                              "reaction needs less; integrator = \"kim-lin\" is stable at any step (seed 001)",
                              rd.explicitDiffusionLimit())
                : std::string("use a smaller time.dt"));
      }
}

template void initialState<2>(const Scene&, RDSolver<2>*);
template void initialState<3>(const Scene&, RDSolver<3>*);
template void applyScene<2>(const Scene&, RDSolver<2>*);
template void applyScene<3>(const Scene&, RDSolver<3>*);
template void checkFinite<2>(const RDSolver<2>&, const std::string&, const std::string&);
template void checkFinite<3>(const RDSolver<3>&, const std::string&, const std::string&);

namespace {

// Every species of `coarse` prolongated onto `fine` (twice the cells per axis).
template <int D>
void prolongateState(const RDSolver<D>& coarse, RDSolver<D>* fine) {
  for (int s = 0; s < fine->species(); ++s)
    prolongate<D>(coarse.field(s), &fine->field(s), fine->settings().boundary == RDBoundary::Periodic);
}

}  // namespace

template <int D>
bool growCoarseToFine(const Scene& scene, RDSolver<D>* rd, const std::function<void(const std::string&)>& log,
                      nlohmann::json* report, const CoarseAdvance<D>& advance) {
  std::unique_ptr<RDSolver<D>> prev;
  for (int level = scene.rd.coarseLevels; level >= 1; --level) {
    RDSettings st = scene.rd.settings;
    for (int& r : st.resolution) r >>= level;
    auto cur = std::make_unique<RDSolver<D>>(st, rd->model());
    if (prev) prolongateState<D>(*prev, cur.get());
    else initialState<D>(scene, cur.get());
    applyScene<D>(scene, cur.get());
    const auto t0 = std::chrono::steady_clock::now();
    const double dt = scene.time.dt * (scene.rd.coarseScaleDt ? std::pow(4.0, level) : 1.0);
    if (advance)
      advance(cur.get(), scene.rd.coarseSteps, dt);
    else
      for (long k = 0; k < scene.rd.coarseSteps; ++k) cur->step(dt);
    checkFinite(*cur, fmt::format("on the coarse grid {}", fmt::join(st.resolution, "x")), "the coarse-to-fine start");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    log(fmt::format("coarse grid {}: {} steps, {:.2f} s", fmt::join(st.resolution, "x"), scene.rd.coarseSteps, wall));
    report->push_back({{"resolution", st.resolution}, {"steps", scene.rd.coarseSteps}, {"dt", dt},
                       {"time", double(scene.rd.coarseSteps) * dt},
                       {"wall_seconds", wall}});
    prev = std::move(cur);
  }
  if (!prev) return false;
  prolongateState<D>(*prev, rd);
  return true;
}

template bool growCoarseToFine<2>(const Scene&, RDSolver<2>*, const std::function<void(const std::string&)>&,
                                  nlohmann::json*, const CoarseAdvance<2>&);
template bool growCoarseToFine<3>(const Scene&, RDSolver<3>*, const std::function<void(const std::string&)>&,
                                  nlohmann::json*, const CoarseAdvance<3>&);

}  // namespace morphoflow
