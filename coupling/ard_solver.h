// ARDSolver<D>: the advection-reaction-diffusion layer of seed 001 sec. 5: a
// reaction-diffusion layer (RDSolver: implicit reaction, then implicit
// diffusion, eq. 6 and 13) whose species are then carried by the fluid's
// velocity (semi-Lagrangian, eq. 19-20). Modes for comparison: passive
// advection only, or reaction-diffusion only, which ignores the flow and its
// obstacles (seed 001 fig. 6: "the ball is not included in the RD simulation").
#pragma once

#include <memory>
#include <array>
#include <string>

#include "coupling/chemical_advection.h"
#include "rd/rd_solver.h"

namespace morphoflow {

template <int D>
class ARDSolver {
 public:
  // rdTimeScale: reaction-diffusion time per unit of fluid time (patterns
  // form on their own clock; seed 001 runs both at one dt).
  ARDSolver(RDSolver<D>* rd, ChemicalAdvector<D> advector, CouplingMode mode, double rdTimeScale = 1.0);

  // One step over dt of fluid time reading the velocity u (seed 001 eq. 6,
  // 19, 20): react and diffuse over rdTimeScale * dt, then advect over dt.
  void step(double dt, const MacVelocity<D>& u);
  // The step's two stages, for a caller that runs them apart (the velocity
  // need not exist before advect): react and diffuse, then advect.
  void reactDiffuse(double dt);
  void advect(double dt, const MacVelocity<D>& u);
  // advect's trace of the feet through u, taken ahead (before reactDiffuse:
  // the feet do not depend on the species), so that u may go before the
  // step ends; advect(dt) then carries the species to those feet.
  void traceAhead(double dt, const MacVelocity<D>& u);
  void advect(double dt);

  RDSolver<D>& rd() { return *rd_; }
  ChemicalAdvector<D>& advector() { return advector_; }
  // Lends the stages' work vectors from `pool` (a caller's that is idle
  // while this layer steps) instead of this layer's own.
  void shareWorkPool(WorkPool* pool);
  const RDSolver<D>& rd() const { return *rd_; }
  CouplingMode mode() const { return mode_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  // Wall seconds of the last step's two stages.
  static constexpr int kStages = 2;
  static constexpr const char* kStageNames[kStages] = {"reaction-diffusion", "advect chemicals"};
  const std::array<double, kStages>& stageSeconds() const { return stageSeconds_; }

 private:
  struct Stages;  // the step's stages (coupling/ard_step.h)
  bool tracedAhead_ = false;
  double traceSeconds_ = 0.0;  // traceAhead's, counted in the advection stage's
  std::vector<Grid<double, D>*> species();

  RDSolver<D>* rd_;
  ChemicalAdvector<D> advector_;
  // The advection's and the RD solves' work vectors, lent to each in turn:
  // this layer's own pool (on the heap, so the RD solver's pointer to it
  // survives a move) or the one shareWorkPool gave.
  std::unique_ptr<WorkPool> own_ = std::make_unique<WorkPool>();
  WorkPool* pool_ = own_.get();
  CouplingMode mode_;
  double rdTimeScale_;
  double time_ = 0.0;
  long steps_ = 0;
  std::array<double, kStages> stageSeconds_{};
};

}  // namespace morphoflow
