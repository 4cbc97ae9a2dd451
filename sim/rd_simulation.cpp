#include "sim/rd_simulation.h"

#include <cmath>

#include <algorithm>
#include <stdexcept>

#include "sim/rd_scene_setup.h"
#include "rd/model_registry.h"
#include "sim/steppers.h"

namespace morphoflow {

template <int D>
std::vector<Grid<float, D>> speciesField(const RDSolver<D>& rd, const std::string& name) {
  const std::vector<std::string>& names = rd.model().info().species;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument("no species '" + name + "'");
  return {toFloat<D>(rd.field(int(it - names.begin())))};
}

template <int D>
bool setSpeciesField(RDSolver<D>* rd, const std::string& name, const Grid<float, D>& values) {
  const std::vector<std::string>& names = rd->model().info().species;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return false;
  Grid<double, D>& g = rd->field(int(it - names.begin()));
  if (values.dims() != g.dims())
    throw UserError({"set_field", 0, 0}, "", "the values of '" + name + "' are not on its grid",
                    "give field()'s shape");
  for (size_t i = 0; i < g.size(); ++i)
    if (!std::isnan(values[i])) g[i] = double(values[i]);  // (NaN: the cell keeps its value)
  return true;
}

template <int D>
void RDSimulation<D>::setField(const std::string& name, const Grid<float, D>& values) {
  host_.refresh();
  if (!setSpeciesField<D>(&rd_, name, values)) Simulation<D>::setField(name, values);
  stepper_->fromHost(rd_);
}

template <int D>
RDSimulation<D>::RDSimulation(const Scene& scene, Backend backend, const Log& log)
    : scene_(scene),
      backend_(backend),
      rd_(scene.rd.settings, *findModel(scene.rd.settings.model)),
      host_([this] { stepper_->toHost(&rd_); }) {
  if (!growCoarseToFine<D>(scene, &rd_, log, &coarseReport_, coarseAdvance<D>(scene, backend)))
    initialState<D>(scene, &rd_);
  applyScene<D>(scene, &rd_);
  stepper_ = makeLayerStepper<D>(scene, backend, &rd_);  // from the state set up here
}

template <int D>
void RDSimulation<D>::advance(double dt, long count) {
  stepper_->advance(dt, count);
  host_.stepped();
}

template <int D>
std::vector<Grid<float, D>> RDSimulation<D>::ownField(const std::string& name) const {
  host_.refresh();
  return speciesField<D>(rd_, name);
}

template <int D>
void RDSimulation<D>::checkFinite(const std::string& when) const {
  host_.refresh();
  const std::string stage = rdStage(rd_.settings());
  morphoflow::checkFinite<D>(rd_, when,
                             backend_ == Backend::Gpu ? "the reaction-diffusion step (gpu, " + stage + ")" : stage);
}

template <int D>
void RDSimulation<D>::save(StateWriter* out) const {
  host_.refresh();
  stepper_->save(out);
}

template <int D>
void RDSimulation<D>::load(const StateReader& in) {
  stepper_->load(in);
  host_.stepped();
}

template <int D>
nlohmann::json RDSimulation<D>::resolved() const {
  nlohmann::json j = resolvedLayer<D>(scene_, rd_);
  stepper_->resolved(&j);
  return j;
}

template <int D>
nlohmann::json resolvedLayer(const Scene& scene, const RDSolver<D>& rd) {
  nlohmann::json j = {{"dimension", D},
                      {"model", rd.model().info().name},
                      {"species", rd.model().info().species},
                      {"resolution", scene.rd.settings.resolution},
                      {"size", scene.rd.settings.size},
                      {"cell_size", rd.h()},
                      {"diffusion", rd.diffusion()},
                      {"dt", scene.time.dt},
                      {"explicit_diffusion_limit", rd.explicitDiffusionLimit()}};
  // Seed 000 sec. 5: the step's spectral radius on this grid, per species, and the largest step within the bound.
  if (const GeneralizedDiffusion* g = rd.generalizedDiffusion()) {
    const double theta = diffusionTheta(rd.settings().integrator);
    nlohmann::json radius = nlohmann::json::object(), largest = nlohmann::json::object();
    for (int s = 0; s < rd.species(); ++s) {
      if (!rd.generalized(s)) continue;
      const double d = rd.diffusion()[size_t(s)], dt = scene.time.dt;
      const std::string& name = rd.model().info().species[size_t(s)];
      radius[name] = g->spectralRadius(dt * d, theta);
      largest[name] = g->largestStableStep(d, theta, 1e6 * dt, scene.rd.generalized.maxSpectralRadius);
    }
    j["generalized_diffusion"] = {{"spectral_radius", radius},
                                  {"max_spectral_radius", scene.rd.generalized.maxSpectralRadius},
                                  {"largest_stable_dt", largest},
                                  {"kernel", g->kernel()}};
  }
  return j;
}

template <int D>
void RDSimulation<D>::report(nlohmann::json* j) const {
  (*j)["coarse_to_fine"] = coarseReport_;
  if (const RDRunStats* stats = stepper_->runStats()) reportRDSolvers(*stats, stepper_->steps(), j);
  stepper_->report(j);
}

void reportRDSolvers(const RDRunStats& stats, long rdSteps, nlohmann::json* j) {
  const double steps = double(rdSteps);
  (*j)["solvers"] = {{"newton_cells", stats.newton.cells},
                     {"newton_failures", stats.newton.failures},
                     {"newton_iterations_max", stats.newton.maxIterations},
                     {"newton_residual_max", stats.newton.maxResidual},
                     {"diffusion_iterations_mean", steps ? double(stats.diffusionIterations) / steps : 0.0},
                     {"diffusion_iterations_max", stats.diffusionMax},
                     {"diffusion_unconverged_steps", stats.unconverged}};
}

template std::vector<Grid<float, 2>> speciesField<2>(const RDSolver<2>&, const std::string&);
template std::vector<Grid<float, 3>> speciesField<3>(const RDSolver<3>&, const std::string&);
template bool setSpeciesField<2>(RDSolver<2>*, const std::string&, const Grid<float, 2>&);
template bool setSpeciesField<3>(RDSolver<3>*, const std::string&, const Grid<float, 3>&);
template nlohmann::json resolvedLayer<2>(const Scene&, const RDSolver<2>&);
template nlohmann::json resolvedLayer<3>(const Scene&, const RDSolver<3>&);
template class RDSimulation<2>;
template class RDSimulation<3>;

}  // namespace morphoflow
