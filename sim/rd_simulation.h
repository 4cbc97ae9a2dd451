// RDSimulation<D>: a reaction-diffusion-only scene (no [fluid]) as a
// Simulation: the scene's initial state (grown coarse to fine where the scene
// asks), its maps and anisotropy, and the solvers' statistics. The steps are
// its LayerStepper's (sim/steppers.h chooses it for the backend: the
// RDSolver's own, the fused float step, or the GPU's); the RDSolver holds the
// state outputs read, refreshed when needed (sim/host_copy.h).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/simulation.h"
#include "sim/host_copy.h"
#include "rd/layer_stepper.h"
#include "rd/rd_solver.h"
#include "scenes/scene.h"
#include "core/backend.h"

namespace morphoflow {

// run.json's "solvers": the Newton and diffusion statistics of `rdSteps` steps.
void reportRDSolvers(const RDRunStats& stats, long rdSteps, nlohmann::json* run);

// run.json's "resolved" values of a scene's RD layer (with the generalized
// diffusion's spectral radius where it has one).
template <int D>
nlohmann::json resolvedLayer(const Scene& scene, const RDSolver<D>& rd);

// The species of an RD layer as fields.
template <int D>
std::vector<Grid<float, D>> speciesField(const RDSolver<D>& rd, const std::string& name);
// Sets species `name` of the layer from float values on its grid; false
// when it has no such species; UserError for values of another shape.
template <int D>
bool setSpeciesField(RDSolver<D>* rd, const std::string& name, const Grid<float, D>& values);

template <int D>
class RDSimulation : public Simulation<D> {
 public:
  using Log = std::function<void(const std::string&)>;
  RDSimulation(const Scene& scene, Backend backend, const Log& log);

  void step(double dt) override { advance(dt, 1); }
  void advance(double dt, long count) override;
  long stepsTogether() const override { return stepper_->stepsTogether(); }
  double time() const override { return stepper_->time(); }
  long steps() const override { return stepper_->steps(); }
  const Scene& scene() const override { return scene_; }
  std::vector<std::string> species() const override { return rd_.model().info().species; }
  void setField(const std::string& name, const Grid<float, D>& values) override;
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 protected:
  std::vector<Grid<float, D>> ownField(const std::string& name) const override;

 private:
  const Scene& scene_;
  Backend backend_;
  mutable RDSolver<D> rd_;
  std::unique_ptr<LayerStepper<D>> stepper_;
  HostCopy host_;
  nlohmann::json coarseReport_ = nlohmann::json::array();
};

}  // namespace morphoflow
