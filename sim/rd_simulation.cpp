#include "sim/rd_simulation.h"

#include <algorithm>
#include <stdexcept>

#include "sim/rd_scene_setup.h"
#include "rd/fused_explicit.h"
#include "rd/model_registry.h"

namespace morphoflow {

void RDRunStats::add(const RDStepStats& st) {
  newton.merge(st.newton);
  diffusionIterations += st.diffusion.iterations;
  diffusionMax = std::max(diffusionMax, st.diffusion.iterations);
  unconverged += st.diffusion.converged ? 0 : 1;
}

void RDRunStats::save(StateWriter* out) const {
  out->put("rd.stats.newton", newton);
  out->put("rd.stats.diffusion_iterations", diffusionIterations);
  out->put("rd.stats.diffusion_max", diffusionMax);
  out->put("rd.stats.unconverged", unconverged);
}

void RDRunStats::load(const StateReader& in) {
  in.get("rd.stats.newton", &newton);
  in.get("rd.stats.diffusion_iterations", &diffusionIterations);
  in.get("rd.stats.diffusion_max", &diffusionMax);
  in.get("rd.stats.unconverged", &unconverged);
}

template <int D>
std::vector<Grid<float, D>> speciesField(const RDSolver<D>& rd, const std::string& name) {
  const std::vector<std::string>& names = rd.model().info().species;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument("no species '" + name + "'");
  return {toFloat<D>(rd.field(int(it - names.begin())))};
}

bool fusedExplicitFits(const Scene& s) { return s.rd.plainExplicit(); }

template <int D>
RDSimulation<D>::RDSimulation(const Scene& scene, const Log& log)
    : scene_(scene), rd_(scene.rd.settings, *findModel(scene.rd.settings.model)) {
  if (!growCoarseToFine<D>(scene, &rd_, log, &coarseReport_)) initialState<D>(scene, &rd_);
  applyScene<D>(scene, &rd_);
  if (fusedExplicitFits(scene)) {
    std::vector<double> p;
    for (size_t k = 0; k < rd_.model().info().parameters.size(); ++k) p.push_back(rd_.parameter(int(k)));
    fused_ = FusedExplicitRD<D>::create(rd_.model().info().name, rd_.cells(), rd_.h(),
                                        rd_.settings().boundary == RDBoundary::Periodic, rd_.diffusion(), p);
    if (fused_ && rd_.generalizedDiffusion()) fused_->setKernel(rd_.generalizedDiffusion()->kernel(), scene.rd.generalized.species);
    if (fused_) toFused();
  }
}

template <int D>
void RDSimulation<D>::toFused() {
  for (int s = 0; s < rd_.species(); ++s) {
    const std::vector<double>& v = rd_.field(s).values();
    std::vector<float>& f = fused_->field(s);
    for (size_t i = 0; i < v.size(); ++i) f[i] = float(v[i]);
  }
  hostStale_ = false;
}

// The float state copied into the RDSolver's fields, for frames, checks and checkpoints.
template <int D>
void RDSimulation<D>::syncHost() const {
  if (!fused_ || !hostStale_) return;
  for (int s = 0; s < rd_.species(); ++s) {
    const std::vector<float>& f = fused_->field(s);
    std::vector<double>& v = rd_.field(s).values();
    for (size_t i = 0; i < v.size(); ++i) v[i] = double(f[i]);
  }
  hostStale_ = false;
}

template <int D>
void RDSimulation<D>::advance(double dt, long count) {
  if (fused_) {
    fused_->step(dt, int(count));
    for (long k = 0; k < count; ++k) time_ += dt;  // (the same sum as step by step)
    steps_ += count;
    hostStale_ = true;
    return;
  }
  for (long k = 0; k < count; ++k) {
    rd_.step(dt);
    stats_.add(rd_.lastStats());
  }
}

template <int D>
std::vector<Grid<float, D>> RDSimulation<D>::field(const std::string& name) const {
  syncHost();
  return speciesField<D>(rd_, name);
}

template <int D>
void RDSimulation<D>::checkFinite(const std::string& when) const {
  syncHost();
  morphoflow::checkFinite<D>(rd_, when, rdStage(rd_.settings()));
}

template <int D>
void RDSimulation<D>::save(StateWriter* out) const {
  syncHost();
  rd_.save(out);
  stats_.save(out);
  if (fused_) out->put("rd.fused.time", time_), out->put("rd.fused.steps", steps_);
}

template <int D>
void RDSimulation<D>::load(const StateReader& in) {
  rd_.load(in);
  stats_.load(in);
  if (fused_) {
    in.get("rd.fused.time", &time_);
    in.get("rd.fused.steps", &steps_);
    toFused();
  }
}

template <int D>
nlohmann::json RDSimulation<D>::resolved() const {
  nlohmann::json j = resolvedLayer<D>(scene_, rd_);
  j["explicit_step"] = fused_ ? "fused, float species (rd/fused_explicit.h)" : "RDSolver, double species";
  if (fused_) j["steps_per_pass"] = fused_->stepsPerPass();  // temporal blocking: several where the state outgrows the caches
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
  reportRDSolvers(stats_, rd_.steps(), j);
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
template nlohmann::json resolvedLayer<2>(const Scene&, const RDSolver<2>&);
template nlohmann::json resolvedLayer<3>(const Scene&, const RDSolver<3>&);
template class RDSimulation<2>;
template class RDSimulation<3>;

}  // namespace morphoflow
