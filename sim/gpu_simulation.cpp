#include "sim/gpu_simulation.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "sim/rd_scene_setup.h"
#include "core/error.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_explicit_rd.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

namespace {

// The first stage of the scene with no GPU program, or "".
std::string missingStage(const Scene& s) {
  const RDScene& rd = s.rd;
  if (s.hasFluid && !rd.enabled) return "";
  if (gpuSpecies(rd.settings.model) == 0) return "the reaction of model " + rd.settings.model;
  if (s.hasFluid && gpuSpecies(rd.settings.model) != 2)
    return "the chemicals' advection for a model of " + std::to_string(gpuSpecies(rd.settings.model)) +
           " species (the coupled gpu step carries two)";
  if (rd.settings.lookupTable) return "the reaction lookup table (rd.lookup_table)";
  if (s.velocity.enabled) return "the layer carried by a given [velocity]";
  if (rd.generalized.enabled) return "generalized (non-Gaussian) diffusion ([rd.generalized])";
  return "";
}

}  // namespace

GpuInfo gpuInfo() {
  GpuInfo g;
  try {
    const GlContext& c = GlContext::instance();
    g = {true, c.renderer(), c.version(), c.platform(), ""};
  } catch (const std::exception& e) {
    g.reason = e.what();
  }
  return g;
}

void recordGlContext(nlohmann::json* run) {
  const GlContext& c = GlContext::instance();
  (*run)["gl_renderer"] = c.renderer();
  (*run)["gl_version"] = c.version();
  (*run)["gl_platform"] = c.platform();
}

void checkGpuRuns(const Scene& scene) {
  const std::string stage = missingStage(scene);
  if (!stage.empty())
    throw UserError({scene.path, 0, 0}, "--backend", "the gpu backend has no program yet for " + stage,
                    "run this scene with --backend tbb; docs/gpu.md lists what the gpu backend runs");
  const GpuInfo g = gpuInfo();
  if (!g.available) throw UserError({"--backend", 0, 0}, "", "no usable GPU context: " + g.reason, "use --backend tbb");
  // Checked before anything is allocated: the fluid's buffers, and the
  // layer's (two float buffers per species for the explicit step).
  size_t cells = 1;
  for (int n : scene.rd.settings.resolution) cells *= size_t(n);
  size_t need = 0;
  if (scene.rd.enabled)  // (the double-precision layer's, an upper bound of the explicit step's)
    need = scene.dimension == 2 ? GpuRDLayer<2>::deviceBytes(cells, gpuSpecies(scene.rd.settings.model))
                                : GpuRDLayer<3>::deviceBytes(cells, gpuSpecies(scene.rd.settings.model));
  if (scene.hasFluid) {
    const std::vector<int>& r = scene.fluid.resolution;
    need += scene.dimension == 2 ? GpuFluid<2>::deviceBytes({r[0], r[1]}) : GpuFluid<3>::deviceBytes({r[0], r[1], r[2]});
  }
  const size_t have = GlContext::instance().availableBytes();
  if (have > 0 && need > have)
    throw UserError({scene.path, 0, 0}, scene.hasFluid ? "grid.resolution" : "rd.resolution",
                    fmt::format("the GPU has {:.0f} MiB free and this scene needs {:.0f} MiB", double(have) / (1 << 20),
                                double(need) / (1 << 20)),
                    "use a smaller grid, or --backend tbb");
}

template <int D>
GpuRDSimulation<D>::GpuRDSimulation(const Scene& scene, const std::function<void(const std::string&)>& log)
    : scene_(scene) {
  // The initial state as the CPU builds it (a coarse-to-fine start's levels
  // stepped on the GPU), then only the GPU steps.
  auto init = std::make_unique<RDSolver<D>>(scene.rd.settings, *findModel(scene.rd.settings.model));
  const CoarseAdvance<D> onGpu = [](RDSolver<D>* level, long steps, double dt) {
    GpuRDLayer<D> layer(*level);
    for (long k = 0; k < steps; ++k) layer.step(dt);
    for (int s = 0; s < level->species(); ++s) level->field(s).values() = layer.download(s);
  };
  if (!growCoarseToFine<D>(scene, init.get(), log, &coarseReport_, onGpu)) initialState<D>(scene, init.get());
  applyScene<D>(scene, init.get());
  species_ = init->model().info().species;
  cells_ = init->field(0).dims();
  explicitLimit_ = init->explicitDiffusionLimit();
  // The plain explicit step in single precision; everything else (every
  // integrator, maps, fixed regions, frozen species, Dirichlet walls) in double.
  const RDScene& rd = scene.rd;
  if (!(rd.plainExplicit() && species_.size() == 2)) {
    host_ = std::move(init);
    layer_ = std::make_unique<GpuRDLayer<D>>(*host_);
    return;
  }
  std::vector<double> params;
  for (size_t k = 0; k < init->model().info().parameters.size(); ++k) params.push_back(init->parameter(int(k)));
  auto values = [&](int s) { return toFloat<D>(init->field(s)).values(); };
  gpu_ = std::make_unique<GpuExplicitRD>(scene.rd.settings, init->diffusion(), params, init->model().info().clamped, values(0),
                                         values(1));
}

template <int D>
std::vector<float> GpuRDSimulation<D>::download(int s) const {
  if (gpu_) return gpu_->download(s);
  const std::vector<double> v = layer_->download(s);
  return std::vector<float>(v.begin(), v.end());
}

template <int D>
GpuRDSimulation<D>::~GpuRDSimulation() = default;

template <int D>
void GpuRDSimulation<D>::step(double dt) {
  if (gpu_)
    gpu_->step(dt);
  else
    layer_->step(dt);
  time_ += dt;
  ++steps_;
}

template <int D>
std::vector<Grid<float, D>> GpuRDSimulation<D>::field(const std::string& name) const {
  for (size_t s = 0; s < species_.size(); ++s)
    if (species_[s] == name) {
      Grid<float, D> g(cells_, 0.0f);
      g.values() = download(int(s));
      return {g};
    }
  throw std::invalid_argument("no species '" + name + "'");
}

template <int D>
void GpuRDSimulation<D>::checkFinite(const std::string& when) const {
  for (size_t s = 0; s < species_.size(); ++s)
    for (float v : download(int(s)))
      if (!std::isfinite(v))
        throw NonFiniteError(fmt::format("the simulation diverged {} in the reaction-diffusion step (gpu, {}): species {} "
                                         "is not finite",
                                         when, rdStage(scene_.rd.settings), species_[s]),
                             gpu_ ? fmt::format("the explicit integrator's limit for this diffusion is time.dt = {:.4g}, and a "
                                                "stiff reaction needs less",
                                                explicitLimit_)
                                  : std::string("use a smaller time.dt"));
}

template <int D>
void GpuRDSimulation<D>::save(StateWriter* out) const {
  out->put("gpu.rd.time", time_);
  out->put("gpu.rd.steps", steps_);
  for (size_t s = 0; s < species_.size(); ++s) {
    if (gpu_)
      out->putVector("gpu.rd.species." + species_[s], gpu_->download(int(s)));
    else
      out->putVector("gpu.rd.layer." + species_[s], layer_->download(int(s)));
  }
  if (layer_) layer_->save(out);
}

template <int D>
void GpuRDSimulation<D>::load(const StateReader& in) {
  in.get("gpu.rd.time", &time_);
  in.get("gpu.rd.steps", &steps_);
  for (size_t s = 0; s < species_.size(); ++s) {
    if (gpu_) {
      std::vector<float> v(gpu_->cells());
      in.getVector("gpu.rd.species." + species_[s], &v);
      gpu_->upload(int(s), v);
    } else {
      std::vector<double> v(layer_->cells());
      in.getVector("gpu.rd.layer." + species_[s], &v);
      layer_->upload(int(s), v);
    }
  }
  if (layer_) layer_->load(in);
}

template <int D>
nlohmann::json GpuRDSimulation<D>::resolved() const {
  return {{"dimension", D},
          {"model", scene_.rd.settings.model},
          {"species", species_},
          {"resolution", scene_.rd.settings.resolution},
          {"size", scene_.rd.settings.size},
          {"dt", scene_.time.dt},
          {"explicit_diffusion_limit", explicitLimit_}};
}

template <int D>
void GpuRDSimulation<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
  if (!coarseReport_.empty()) (*run)["coarse_to_fine"] = coarseReport_;
}

template class GpuRDSimulation<2>;
template class GpuRDSimulation<3>;

}  // namespace morphoflow
