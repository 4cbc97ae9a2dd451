// FluidSolver<D>: Stam's stable fluids as a fixed sequence of named, timed
// stages (forces, advect, diffuse, project), written once for 2D and 3D.
// A passive dye rides along for rendering and buoyancy; with [smoke] it is
// the smoke density, beside a temperature, sources and confinement (smoke.h).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>

#include "core/mac_velocity.h"
#include "core/state_archive.h"
#include "fluid/advection.h"
#include "fluid/fluid_settings.h"
#include "fluid/obstacle_placement.h"
#include "fluid/pressure_projection.h"
#include "fluid/surface_forces.h"
#include "fluid/velocity_constraints.h"
#include "fluid/viscosity.h"

namespace morphoflow {

struct FluidStepStats {
  static constexpr int kStages = 4;
  static constexpr const char* kStageNames[kStages] = {"forces", "advect", "diffuse", "project"};
  std::array<double, kStages> seconds{};  // wall time of each stage in this step
  SolverResult pressure;
  SolverResult viscosity;
  double viscosityCellUpdates = 0.0;  // its solves' iterations times unknowns, over the components
  bool viscosityUsedCG = false;       // multigrid-preconditioned CG solved (else the Chebyshev iteration)
};

template <int D>
class FluidSolver {
 public:
  // Throws std::invalid_argument when the settings are inconsistent.
  explicit FluidSolver(const FluidSettings& settings);

  // afterAdvection (if given) runs once the step's advection is done, on the
  // step's thread: from then on advectedVelocity() holds what it advected.
  void step(double dt, const std::function<void()>& afterAdvection = {});
  // Whether an obstacle moves (obstacles.N.motion or rotation).
  bool movesObstacles() const { return moves_; }
  // Puts the moving obstacles where the coming step of dt ends (step()
  // does it itself unless this ran first, so that a coupled layer can
  // follow the solid before the step).
  void placeObstaclesFor(double dt) { placeObstacles(time_ + dt, true); }
  // Largest dt with |u|max dt <= cfl h (dtMax when the fluid is at rest).
  double cflTimeStep(double cfl, double dtMax) const;
  double maxSpeed() const;

  const FluidSettings& settings() const { return settings_; }
  const IVec<D>& cells() const { return cells_; }
  double h() const { return h_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  const MacVelocity<D>& velocity() const { return u_; }
  MacVelocity<D>& velocity() { return u_; }
  // The velocity the step's advection traced through (the step's start
  // velocity with its forces applied), from the advection until the step
  // releases it, right after afterAdvection (its storage goes back to the
  // pool the later stages borrow from; afterAdvection may release it
  // sooner), or until the next step's advection after
  // keepAdvectedVelocity(true) (a caller reading it beside the later
  // stages or after the step).
  const MacVelocity<D>& advectedVelocity() const { return scratch_; }
  void releaseAdvectedVelocity();
  void keepAdvectedVelocity(bool keep) { keepsAdvected_ = keep; }
  WorkPool* workPool() { return &pool_; }
  // The dye (zeros until something puts dye in: a scene without dye keeps no
  // grid for it until asked for one).
  Grid<float, D>& dye() { return materialisedDye(); }
  const Grid<float, D>& dye() const { return materialisedDye(); }
  bool hasDye() const { return !dye_.empty(); }
  // The smoke's temperature (empty unless the scene has [smoke]); the smoke
  // density is the dye.
  const Grid<float, D>& temperature() const { return temperature_; }
  Grid<float, D>& temperature() { return temperature_; }
  const Grid<uint8_t, D>& solid() const { return constraints_.solid; }
  const VelocityConstraints<D>& constraints() const { return constraints_; }
  // The cut obstacles' surface, one element per cut cell (made on first use).
  const std::vector<SurfaceElement>& cutSurface() const {
    if (!cutSurfaceMade_) cutSurface_ = cutSurfaceElements<D>(constraints_), cutSurfaceMade_ = true;
    return cutSurface_;
  }
  Grid<float, D> pressure() const { return projection_->pressure(); }
  const FluidStepStats& lastStats() const { return stats_; }
  PressureProjection<D>& projection() { return *projection_; }
  // Everything step() reads besides the settings (velocity, dye, time,
  // the solvers' warm starts), so that load(save()) continues bit for bit.
  void save(StateWriter* out) const;
  void load(const StateReader& in);
  // The clock and last pressure of steps taken elsewhere (the GPU backend,
  // which sets velocity() and dye() itself), so that fields, probes and
  // save() describe them.
  void adopt(double time, long steps, const std::vector<double>& phi, double dt);
  Layout<D> cellLayout() const { return Layout<D>::cellCentred(h_, cells_, constraints_.periodic()); }

 private:
  struct Stages;  // the step's stages (fluid/fluid_step.h)
  void placeObstacles(double t, bool fill);
  void injectInflowDye();
  void advectScalar(Grid<float, D>* field, double dt, const std::optional<std::array<int, D>>& reach);
  Grid<float, D>& materialisedDye() const {
    if (dye_.empty()) dye_ = Grid<float, D>(cells_, 0.0f);
    return dye_;
  }

  FluidSettings settings_;
  IVec<D> cells_;
  double h_;
  VelocityConstraints<D> constraints_;
  std::unique_ptr<PressureProjection<D>> projection_;
  std::unique_ptr<ViscositySolver<D>> viscosity_;
  MacVelocity<D> u_, scratch_;
  mutable Grid<float, D> dye_;  // empty: all zero
  Grid<float, D> dyeScratch_;
  Grid<float, D> temperature_;                    // [smoke] only
  std::vector<Grid<float, D>> sourceCoverage_;    // per smoke source
  mutable std::vector<SurfaceElement> cutSurface_;
  mutable bool cutSurfaceMade_ = false;
  AdvectionScratch<D> advectionScratch_;
  WorkPool pool_;  // the stages' work vectors, lent to each in turn
  bool keepsAdvected_ = false;  // scratch_ kept between steps (keepAdvectedVelocity)
  double time_ = 0.0;
  long steps_ = 0;
  ObstaclePlacement<D> placement_;
  bool moves_ = false;
  FluidStepStats stats_;
};

}  // namespace morphoflow
