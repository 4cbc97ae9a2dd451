// GivenFlowSimulation<D>: a scene's reaction-diffusion layer carried by a
// given velocity ([velocity]: expressions or a VDB sequence) instead of a
// fluid (flow visualisation, seed 004 sec. 3, fig. 24). Each step samples the
// velocity at the step's start (as the coupled run's ARD step reads velocity
// n), maps its speed to the parameters the scene names and its direction to
// the diffusion tensor, then takes the ARD step (seed 001 eq. 6, 13, 19-20).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sim/rd_simulation.h"
#include "coupling/ard_solver.h"
#include "coupling/given_velocity.h"
#include "rd/diffusion_tensor.h"
#include "scenes/scene.h"

namespace morphoflow {

template <int D>
class GivenFlowSimulation : public Simulation<D> {
 public:
  explicit GivenFlowSimulation(const Scene& scene);
  // With the velocity from `source` (a scene whose [velocity] has python = true).
  GivenFlowSimulation(const Scene& scene, std::unique_ptr<GivenVelocity<D>> source);

  void step(double dt) override;
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  const Scene& scene() const override { return scene_; }
  std::vector<std::string> species() const override { return rd_.model().info().species; }
  // The source's field changed (Python's set_velocity): sampled again now.
  void velocityChanged() {
    sampled_ = false;
    sampleVelocity(time_);
  }
  void setField(const std::string& name, const Grid<float, D>& values) override {
    if (!setSpeciesField<D>(&rd_, name, values)) Simulation<D>::setField(name, values);
  }
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 protected:
  std::vector<Grid<float, D>> ownField(const std::string& name) const override;

 private:
  void sampleVelocity(double t);
  void checkVelocityFinite(double t) const;
  void applyVelocityMaps();
  Vec<D> velocityAt(const IVec<D>& cell) const;

  const Scene& scene_;
  RDSolver<D> rd_;
  std::unique_ptr<ARDSolver<D>> ard_;
  std::unique_ptr<GivenVelocity<D>> source_;
  MacVelocity<D> u_;
  bool sampled_ = false;
  double referenceSpeed_ = 0.0;     // of the speed maps (the scene's, or the first sample's largest)
  std::vector<double> lambda1_, lambda2_;  // the tensor's fields, for direction = "velocity"
  double time_ = 0.0;
  long steps_ = 0;
  RDRunStats stats_;
};

}  // namespace morphoflow
