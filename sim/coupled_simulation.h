// CoupledSimulation<D>: a scene's stable fluid carrying its
// advection-reaction-diffusion layer (seed 001 sec. 5, 7), stepped by the
// serial or tbb-overlap scheduler (coupling/coupled_stepper.h), as a
// Simulation: species and fluid fields, and the time each side took. On the
// gpu backend the steps are the GPU's (GpuFluid, GpuARDSolver) and the CPU
// solvers hold a copy of the state, refreshed when a field or checkpoint needs it.
#pragma once

#include <memory>
#include <functional>
#include <string>
#include <vector>

#include "sim/rd_simulation.h"
#include "core/simulation.h"
#include "coupling/coupled_stepper.h"
#include "scenes/scene.h"

namespace morphoflow {

template <int D>
class CoupledSimulation : public Simulation<D> {
 public:
  using Warn = std::function<void(const std::string&)>;
  CoupledSimulation(const Scene& scene, CouplingBackend backend, Warn warn, bool gpu = false);
  ~CoupledSimulation() override;

  void step(double dt) override;
  double cflTimeStep(double cfl, double dtMax) const override;
  double time() const override { return gpu_ ? time_ : fluid_.time(); }
  long steps() const override { return gpu_ ? steps_ : fluid_.steps(); }
  std::vector<std::string> fieldNames() const override;
  std::vector<std::string> species() const override { return rd_.model().info().species; }
  std::vector<std::string> dumpFieldNames() const override { return species(); }
  std::vector<Grid<float, D>> field(const std::string& name) const override;
  bool symmetric(const std::string& name) const override { return name == "vorticity" && D == 2; }
  bool hasObstacles() const override { return !scene_.fluid.obstacles.empty(); }
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 private:
  struct Gpu;  // the GPU's fluid, layer and ARD step
  void syncHost() const;
  void stepGpu(double dt);

  const Scene& scene_;
  CouplingBackend backend_;
  Warn warn_;
  mutable FluidSolver<D> fluid_;
  mutable RDSolver<D> rd_;
  std::unique_ptr<Gpu> gpu_;
  double time_ = 0.0;  // gpu: the clock of the GPU's steps
  long steps_ = 0;
  mutable bool hostStale_ = false;
  std::unique_ptr<ARDSolver<D>> ard_;
  std::unique_ptr<CoupledStepper<D>> stepper_;
  double fluidSeconds_ = 0, ardSeconds_ = 0, stepSeconds_ = 0;
  long pressureIterations_ = 0, diffusionIterations_ = 0;
  int unconverged_ = 0;
};

}  // namespace morphoflow
