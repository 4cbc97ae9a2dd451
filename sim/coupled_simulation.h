// CoupledSimulation<D>: a scene's stable fluid carrying its
// advection-reaction-diffusion layer (seed 001 sec. 5, 7), stepped by the
// CoupledStepper that sim/steppers.h chooses for the backend (the CPU's serial
// or tbb-overlap schedule, coupling/cpu_coupled_stepper.h, or the GPU's), as a
// Simulation: species and fluid fields, and the time each side took. The
// FluidSolver and RDSolver hold the state outputs read, refreshed when a
// field or checkpoint needs it (sim/host_copy.h).
#pragma once

#include <memory>
#include <functional>
#include <string>
#include <vector>

#include "sim/rd_simulation.h"
#include "sim/simulation.h"
#include "sim/host_copy.h"
#include "coupling/ard_solver.h"
#include "coupling/coupled_stepper.h"
#include "scenes/scene.h"
#include "core/backend.h"

namespace morphoflow {

template <int D>
class CoupledSimulation : public Simulation<D> {
 public:
  using Warn = std::function<void(const std::string&)>;
  CoupledSimulation(const Scene& scene, Backend backend, Warn warn);
  ~CoupledSimulation() override;

  void step(double dt) override;
  double cflTimeStep(double cfl, double dtMax) const override;
  double time() const override { return stepper_->fluid().time(); }
  long steps() const override { return stepper_->fluid().steps(); }
  const Scene& scene() const override { return scene_; }
  std::vector<std::string> species() const override { return rd_.model().info().species; }
  void setField(const std::string& name, const Grid<float, D>& values) override;
  bool hasObstacles() const override { return !scene_.fluid.obstacles.empty(); }
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 protected:
  std::vector<Grid<float, D>> ownField(const std::string& name) const override;

 private:
  const Scene& scene_;
  Warn warn_;
  mutable FluidSolver<D> fluid_;
  mutable RDSolver<D> rd_;
  std::unique_ptr<ARDSolver<D>> ard_;
  std::unique_ptr<CoupledStepper<D>> stepper_;
  HostCopy host_;
  double fluidSeconds_ = 0, ardSeconds_ = 0, stepSeconds_ = 0;
  long pressureIterations_ = 0, diffusionIterations_ = 0;
  int unconverged_ = 0;
  std::vector<Grid<float, D>> sourceCoverage_;  // [smoke]: each source's cover of the RD cells
  SmokeTaps<D> smokeTaps_;                      // [smoke]: the smoke's taps at the RD cells
  void smokeOnLayer(double dt);
};

}  // namespace morphoflow
