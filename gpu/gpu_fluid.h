// The stable fluid (fluid/fluid_solver.h) on the GPU: the same stages in the
// same order (fluid/fluid_step.h), each a class of gpu/fluid/ named after
// its CPU file (advection, viscosity, projection, smoke), on the same MAC
// grid (gpu/fluid/gpu_mac_grid.h), with
// the CPU's boundary handling (walls, moving lids, inflow, outflow, periodic
// axes, obstacles) taken from the same VelocityConstraints. Advection is
// semi-Lagrangian, MacCormack or BFECC; viscosity is implicit (diagonally
// preconditioned CG: the identity term keeps it well conditioned); the
// pressure is solved by MGPCG to the scene's relative tolerance. The fields
// stay on the GPU and leave it only when asked for (toHost). What it takes
// from the CPU is read once, at construction: the settings and the
// assembled VelocityConstraints (fixed faces, prescribed values, solids,
// periodic axes); nothing of the CPU solver is read while stepping. Moving
// obstacles are placed on the host by this fluid's own ObstaclePlacement
// at every step (their geometry depends on the time alone) and what they
// change is uploaded; the cells they uncover are filled on the device.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "core/backend.h"
#include "core/mac_velocity.h"
#include "core/solver_result.h"
#include "core/state_archive.h"
#include "fluid/fluid_settings.h"
#include "fluid/fluid_solver.h"
#include "fluid/fluid_stepper.h"
#include "fluid/obstacle_placement.h"
#include "fluid/velocity_constraints.h"
#include "fluid/viscosity.h"
#include "gpu/fluid/gpu_advection.h"
#include "gpu/fluid/gpu_mac_grid.h"
#include "gpu/fluid/gpu_obstacles.h"
#include "gpu/fluid/gpu_projection.h"
#include "gpu/fluid/gpu_smoke.h"
#include "gpu/fluid/gpu_viscosity.h"
#include "gpu/gpu_buffer.h"
#include "gpu/gpu_counts.h"
#include "gpu/gpu_stage_timer.h"
#include "gpu/kernel_modes.h"

namespace morphoflow {

class ComputeProgram;

template <int D>
class GpuFluid final : public FluidStepper<D> {
 public:
  // `real`: the pressure, the viscosity's vectors and their solvers' (gpu.precision); the velocity is float.
  GpuFluid(const FluidSettings& settings, const VelocityConstraints<D>& constraints,
           GpuPrecision real = GpuPrecision::Double);
  ~GpuFluid() override;
  GpuFluid(const GpuFluid&) = delete;
  GpuFluid& operator=(const GpuFluid&) = delete;

  void step(double dt) override;
  // Whether an obstacle moves (obstacles.N.motion or rotation).
  bool movesObstacles() const { return placement_.moves(); }
  // Puts the moving obstacles where the coming step of dt ends (step() does
  // it itself unless this ran first, so that a coupled layer can follow the
  // solid before the step), as FluidSolver::placeObstaclesFor.
  void placeObstaclesFor(double dt) { placeObstacles(time_ + dt, true); }
  // The solid cells where the moving obstacles are (with none moving: empty).
  const Grid<uint8_t, D>& movingSolid() const { return vc_.solid; }
  double h() const { return grid_.h; }
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  // The solvers' results, and each stage's time on the GPU in the step
  // before (timer queries: timing never waits on the GPU). The solves
  // decide their convergence on the device (gpu_gate.h); their results are
  // read at steps 1, 2, 4, 8 and then every 16th (statsDue, at the end of
  // the projection) and at every read-back of the state (frames,
  // checkpoints): each step reports the last read's (the most iterations a
  // solve took since the read before, whether all converged, the largest
  // residual).
  const FluidStepStats& lastStats() const override { return stats_; }
  // Whether the velocity is finite (the speed's reduction: a NaN or infinity makes it infinite).
  bool finite() const override { return std::isfinite(maxSpeed()); }
  // sqrt(D) max_a max |u_a|, as FluidSolver::maxSpeed (a bound of the speed):
  // one read-back a step, shared by finite() and cflTimeStep().
  double maxSpeed() const;
  // Largest dt with maxSpeed() dt <= cfl h (dtMax when the fluid is at rest), as FluidSolver's.
  double cflTimeStep(double cfl, double dtMax) const override;
  // Bytes of device memory a fluid of these cells allocates.
  static size_t deviceBytes(const IVec<D>& cells, GpuPrecision real);
  size_t deviceBytes() const;  // this fluid's (its cells and precision)
  GpuPrecision precision() const { return real_; }
  // The solves' tolerances (the scene's, raised to the precision's floor): {"pressure", "viscosity"}.
  nlohmann::json tolerances() const {
    return {{"pressure", settings_.pressureTolerance}, {"viscosity", settings_.viscosityTolerance}};
  }

  void upload(const MacVelocity<D>& u, const Grid<float, D>& dye, const Grid<float, D>* temperature = nullptr);
  void download(MacVelocity<D>* u, Grid<float, D>* dye, Grid<float, D>* temperature = nullptr) const;
  // phi of the last projection (p = rho phi / dt), and that dt.
  std::vector<double> phi() const;
  double lastDt() const { return projection_.lastDt(); }
  // The velocity buffer (component a at offset(a) floats) for the chemicals' advection.
  const GpuBuffer& velocity() const { return grid_.vel; }
  // The velocity the last step's advection traced through (its start
  // velocity with its forces applied: FluidSolver::advectedVelocity), kept
  // until the next step's advection.
  const GpuBuffer& advectedVelocity() const { return grid_.velScratch; }
  // The dye (the smoke, with [smoke]), cell-centred.
  const GpuBuffer& dye() const { return dye_; }
  // The stages' dispatches and host waits (gpu_counts.h).
  const GpuStageTimer& stageTimer() const { return *timer_; }
  size_t offset(int a) const { return grid_.off[size_t(a)]; }
  // The velocity, dye, clock and last projection into `host`; the velocity, dye and clock from it.
  void toHost(FluidSolver<D>* host) const override;
  void fromHost(const FluidSolver<D>& host) override;
  // Everything step() reads besides the settings and the fields (checkpoints).
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  // run.json: the GL context and the pressure solver.
  void report(nlohmann::json* run) const override;

 private:
  struct Stages;  // the step's stages (fluid/fluid_step.h)
  void forces(double dt);
  void advect(double dt);
  void injectInflowDye();
  void readSolverStats() const;  // the solves' tallies into stats_
  void placeObstacles(double t, bool fill);
  // The constraints the device's are made from: the given ones, or with a
  // moving obstacle this fluid's own, placed at its time (placement_).
  const VelocityConstraints<D>& constraints(const VelocityConstraints<D>& given) const {
    return placement_.moves() ? vc_ : given;
  }

  FluidSettings settings_;
  GpuPrecision real_;
  double time_ = 0.0;
  long steps_ = 0;
  // A moving obstacle's geometry, placed on the host at every step (it
  // depends on the time alone; the host's systems follow it) and the grid's
  // flags, values, fractions and flux on the device (obstacles_): nothing
  // is read back.
  ObstaclePlacement<D> placement_;
  VelocityConstraints<D> vc_;
  // the stages, one a CPU file (gpu/fluid/)
  GpuMacGrid<D> grid_;
  std::unique_ptr<GpuObstacles<D>> obstacles_;  // with a moving obstacle
  GpuAdvection<D> advection_;
  mutable GpuViscosity<D> viscosity_;
  mutable GpuProjection<D> projection_;
  std::unique_ptr<GpuSmoke<D>> smoke_;  // with [smoke]
  GpuBuffer dye_, dyeScratch_;
  bool dyeActive_ = false;
  mutable FluidStepStats stats_;
  mutable double speed_cached_ = -1.0;  // maxSpeed() of the current velocity (-1: not yet read)
  std::unique_ptr<class GpuReduction> speed_;
  std::unique_ptr<class GpuStageTimer> timer_;
  StepCounts counts_;
};

}  // namespace morphoflow
