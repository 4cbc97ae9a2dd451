#include "sim/coupled_simulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "core/parallel.h"
#include "core/sampling.h"
#include "coupling/solid_on_layer.h"
#include "fluid/smoke.h"
#include "rd/model_registry.h"
#include "sim/fluid_simulation.h"
#include "sim/rd_scene_setup.h"
#include "sim/steppers.h"

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
  Grid<uint8_t, D> mask = solidOnLayer<D>(fluid.solid(), fluid.h(), d.cells, d.h);
  bool any = fluid.movesObstacles();  // (a moving obstacle's cells are followed, even from none)
  for (uint8_t m : mask.values()) any |= m != 0;
  if (any) d.solid = std::move(mask.values());
  return d;
}

}  // namespace

template <int D>
CoupledSimulation<D>::CoupledSimulation(const Scene& scene, Backend backend, Warn warn)
    : scene_(scene),
      warn_(std::move(warn)),
      fluid_(scene.fluid),
      rd_(scene.rd.settings, *findModel(scene.rd.settings.model)),
      host_([this] { stepper_->toHost(&fluid_, &rd_); }) {
  checkFluidLeft<D>(scene, fluid_);
  warnOfEmptySources<D>(scene, fluid_, warn_);
  initialState<D>(scene, &rd_);
  applyScene<D>(scene, &rd_);
  const CouplingScene& C = scene.coupling;
  const ChemicalDomain<D> domain = chemicalDomain<D>(scene, fluid_, rd_);
  ard_ = std::make_unique<ARDSolver<D>>(&rd_, ChemicalAdvector<D>(domain, C.interpolation), C.mode, C.rdTimeScale);
  stepper_ = makeCoupledStepper<D>(scene, backend, &fluid_, ard_.get(), domain);  // from the state set up here
  if (scene.fluid.smoke.enabled) {
    sourceCoverage_ =
        sourceCoverage<D>(scene.fluid.smoke.sources, rd_.cells(), rd_.h(), Grid<uint8_t, D>(rd_.cells(), 0));
    smokeTaps_ = smokeTaps<D>(fluid_.cellLayout(), fluid_.cells(), rd_.cells(), rd_.h());
  }
}

// The pattern on the smoke (coupling/smoke_layer.h), on the backend's
// layer: sources blend their chemicals in while they emit, then the mask
// holds the layer at its rest state (smoke_values) outside the smoke.
template <int D>
void CoupledSimulation<D>::smokeOnLayer(double dt) {
  const SmokeSettings& sm = scene_.fluid.smoke;
  const CouplingScene& C = scene_.coupling;
  const double t0 = time() - dt;
  for (size_t q = 0; q < sm.sources.size(); ++q) {
    const SmokeSource& src = sm.sources[q];
    if (src.chemicals.empty() || !(std::min(t0 + dt, src.end) > std::max(t0, src.start))) continue;
    if (src.motion.empty())
      stepper_->blendLayer(int(q), sourceCoverage_[q], src.chemicals);
    else
      stepper_->blendLayer(-1,
                           sourceCover<D>(src, t0 + 0.5 * dt, rd_.cells(), rd_.h(), Grid<uint8_t, D>(rd_.cells(), 0)),
                           src.chemicals);
  }
  if (C.smokeMask >= 0.0) stepper_->maskLayer(smokeTaps_, C.smokeMask, C.smokeValues);
}

template <int D>
CoupledSimulation<D>::~CoupledSimulation() = default;

template <int D>
double CoupledSimulation<D>::cflTimeStep(double cfl, double dtMax) const {
  return stepper_->fluid().cflTimeStep(cfl, dtMax);
}

template <int D>
void CoupledSimulation<D>::step(double dt) {
  stepper_->step(dt);
  if (scene_.fluid.smoke.enabled) smokeOnLayer(dt);
  host_.stepped();
  const std::array<double, 3> sec = stepper_->seconds();
  fluidSeconds_ += sec[0];
  ardSeconds_ += sec[1];
  stepSeconds_ += sec[2];
  const FluidStepStats& fs = stepper_->fluid().lastStats();
  pressureIterations_ += fs.pressure.iterations;
  diffusionIterations_ += stepper_->layerStats().diffusion.iterations;
  const SolverResult& pressure = fs.pressure;
  if (!pressure.converged && unconverged_++ == 0)
    warn_(fmt::format("warning: step {}: pressure solve stopped at relative residual {:.2e} after {} iterations",
                      steps(), pressure.residual, pressure.iterations));
  if (!stepper_->fluid().finite())
    throw NonFiniteError(
        fmt::format("the simulation diverged at step {} in the fluid step: the velocity is not finite", steps()),
        "use a smaller time.dt or set time.cfl, and check the forces and boundary speeds");
}

template <int D>
void CoupledSimulation<D>::setField(const std::string& name, const Grid<float, D>& values) {
  host_.refresh();
  if (!setSpeciesField<D>(&rd_, name, values) && !setFluidField<D>(&fluid_, name, values))
    Simulation<D>::setField(name, values);
  stepper_->fromHost(fluid_, rd_);
}

template <int D>
std::vector<Grid<float, D>> CoupledSimulation<D>::ownField(const std::string& name) const {
  host_.refresh();
  const std::vector<std::string> sp = species();
  if (std::find(sp.begin(), sp.end(), name) != sp.end()) return speciesField<D>(rd_, name);
  return fluidField<D>(fluid_, name);
}

template <int D>
void CoupledSimulation<D>::checkFinite(const std::string& when) const {
  host_.refresh();
  checkFluidFinite<D>(fluid_, when);
  morphoflow::checkFinite<D>(rd_, when, "the advection-reaction-diffusion step (" + rdStage(rd_.settings()) + ")");
}

template <int D>
void CoupledSimulation<D>::save(StateWriter* out) const {
  host_.refresh();
  fluid_.save(out);
  rd_.save(out);
  stepper_->save(out);
  out->put("coupled.stats.seconds", std::array<double, 3>{fluidSeconds_, ardSeconds_, stepSeconds_});
  out->put("coupled.stats.iterations", std::array<long, 2>{pressureIterations_, diffusionIterations_});
  out->put("coupled.stats.unconverged", unconverged_);
}

template <int D>
void CoupledSimulation<D>::load(const StateReader& in) {
  fluid_.load(in);
  rd_.load(in);
  stepper_->fromHost(fluid_, rd_);
  stepper_->load(in);
  std::array<double, 3> s{};
  std::array<long, 2> it{};
  in.get("coupled.stats.seconds", &s);
  in.get("coupled.stats.iterations", &it);
  in.get("coupled.stats.unconverged", &unconverged_);
  fluidSeconds_ = s[0], ardSeconds_ = s[1], stepSeconds_ = s[2];
  pressureIterations_ = it[0], diffusionIterations_ = it[1];
}

template <int D>
nlohmann::json CoupledSimulation<D>::resolved() const {
  const CouplingScene& C = scene_.coupling;
  return {{"dimension", D},
          {"resolution", scene_.fluid.resolution},
          {"size", scene_.fluid.size},
          {"reynolds", scene_.reynolds},
          {"model", rd_.model().info().name},
          {"species", species()},
          {"rd_resolution", scene_.rd.settings.resolution},
          {"rd_cell_size", rd_.h()},
          {"diffusion", rd_.diffusion()},
          {"coupling_mode", couplingModeName(C.mode)},
          {"interpolation", interpolationName(C.interpolation)},
          {"rd_time_scale", C.rdTimeScale},
          {"dt", scene_.time.dt},
          {"cfl", scene_.time.cfl}};
}

template <int D>
void CoupledSimulation<D>::report(nlohmann::json* j) const {
  const double steps = double(this->steps());
  stepper_->report(j);
  (*j)["coupling"] = {{"fluid_seconds", fluidSeconds_},
                      {"ard_seconds", ardSeconds_},
                      {"step_seconds", stepSeconds_},
                      {"overlapped", stepper_->overlapped()}};
  (*j)["solvers"] = {{"pressure_iterations_mean", steps ? double(pressureIterations_) / steps : 0.0},
                     {"pressure_unconverged_steps", unconverged_},
                     {"diffusion_iterations_mean", steps ? double(diffusionIterations_) / steps : 0.0}};
}

template class CoupledSimulation<2>;
template class CoupledSimulation<3>;

}  // namespace morphoflow
