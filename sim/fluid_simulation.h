// FluidSimulation<D>: a scene's stable fluid (fluid/fluid_solver.h) as a
// Simulation, with its dye, probes (centreline profiles, obstacle forces,
// the Strouhal number) and solver statistics. The steps are its
// FluidStepper's (sim/steppers.h chooses it for the backend); the
// FluidSolver holds the state outputs read, refreshed when a field, probe or
// checkpoint needs it (sim/host_copy.h).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sim/simulation.h"
#include "sim/host_copy.h"
#include "fluid/fluid_solver.h"
#include "fluid/fluid_stepper.h"
#include "scenes/scene.h"
#include "core/backend.h"

namespace morphoflow {

// The scene's initial dye (stripes or a checkerboard), outside the solids.
template <int D>
void initialiseDye(const Scene& scene, FluidSolver<D>* fluid);

// Refuses (UserError naming [[obstacles]]) a scene whose obstacles cover every cell.
template <int D>
void checkFluidLeft(const Scene& scene, const FluidSolver<D>& fluid);

// Warns of each fixed source that covers no fluid cell (it would emit nothing).
template <int D>
void warnOfEmptySources(const Scene& scene, const FluidSolver<D>& fluid,
                        const std::function<void(const std::string&)>& warn);

// Throws NonFiniteError when a velocity component or the dye is not finite.
template <int D>
void checkFluidFinite(const FluidSolver<D>& fluid, const std::string& where);

// A field of the fluid's (scenes/field_catalogue.h).
template <int D>
std::vector<Grid<float, D>> fluidField(const FluidSolver<D>& fluid, const std::string& name);
// Sets the dye (the smoke) or, in a smoke scene, the temperature from values
// on the fluid's grid; false for another name; UserError for another shape.
template <int D>
bool setFluidField(FluidSolver<D>* fluid, const std::string& name, const Grid<float, D>& values);

template <int D>
class FluidSimulation : public Simulation<D> {
 public:
  using Warn = std::function<void(const std::string&)>;
  FluidSimulation(const Scene& scene, Backend backend, Warn warn);

  void step(double dt) override;
  double cflTimeStep(double cfl, double dtMax) const override;
  double time() const override { return stepper_->time(); }
  long steps() const override { return stepper_->steps(); }
  const Scene& scene() const override { return scene_; }
  void setField(const std::string& name, const Grid<float, D>& values) override {
    host_.refresh();
    if (!setFluidField<D>(&fluid_, name, values)) Simulation<D>::setField(name, values);
    stepper_->fromHost(fluid_);
  }
  bool hasObstacles() const override { return !scene_.fluid.obstacles.empty(); }
  void checkFinite(const std::string& when) const override {
    host_.refresh();
    checkFluidFinite<D>(fluid_, when);
  }
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;
  // The probes' files: profiles/*.csv, forces.csv.
  std::vector<std::pair<std::string, std::string>> measurementFiles() const override;

 protected:
  std::vector<Grid<float, D>> ownField(const std::string& name) const override {
    host_.refresh();
    return fluidField<D>(fluid_, name);
  }

 private:
  const Scene& scene_;
  Warn warn_;
  mutable FluidSolver<D> fluid_;
  std::unique_ptr<FluidStepper<D>> stepper_;
  HostCopy host_;
  int flowAxis_ = -1, liftAxis_ = 1;  // (the inflow's axis, or a towed body's)
  double dragSign_ = 1.0;             // -1: a body towed along +axis, whose drag points back
  // Statistics over the run, and the force probe's signal.
  std::array<double, FluidStepStats::kStages> stageTotals_{};
  long pressureIterations_ = 0, viscosityIterations_ = 0;
  int maxPressureIterations_ = 0, unconverged_ = 0;
  double maxPressureResidual_ = 0;
  std::vector<double> forceTime_, drag_, lift_;
};

}  // namespace morphoflow
