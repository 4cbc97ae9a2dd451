#include "coupling/ard_solver.h"

#include <stdexcept>

#include "core/stage_trace.h"
#include "coupling/ard_step.h"

namespace morphoflow {

template <int D>
ARDSolver<D>::ARDSolver(RDSolver<D>* rd, ChemicalAdvector<D> advector, CouplingMode mode, double rdTimeScale)
    : rd_(rd), advector_(std::move(advector)), mode_(mode), rdTimeScale_(rdTimeScale) {
  if (!(rdTimeScale > 0)) throw std::invalid_argument("coupling: the reaction-diffusion time scale must be > 0");
  if (advector_.domain().cells != rd->cells()) throw std::invalid_argument("coupling: advection and RD grids differ");
  if (mode_ != CouplingMode::RDOnly) advector_.emptySolids(species());
  rd_->setWorkPool(pool_);
}

template <int D>
void ARDSolver<D>::shareWorkPool(WorkPool* pool) {
  pool_ = pool;
  rd_->setWorkPool(pool);
}

template <int D>
std::vector<Grid<double, D>*> ARDSolver<D>::species() {
  std::vector<Grid<double, D>*> s;
  for (int k = 0; k < rd_->species(); ++k) s.push_back(&rd_->field(k));
  return s;
}

// The CPU's stages of the ARD step, whose order is coupling/ard_step.h's.
template <int D>
struct ARDSolver<D>::Stages {
  ARDSolver& s;
  const MacVelocity<D>* u = nullptr;
  void reactDiffuse(double dt) { s.rd_->step(dt); }
  void emptySolids() { s.advector_.emptySolids(s.species()); }
  void advect(double dt) {
    if (u) s.advector_.advect(*u, dt, s.species(), s.pool_);
    else s.advector_.carry(s.species(), s.pool_);
  }
};

template <int D>
void ARDSolver<D>::step(double dt, const MacVelocity<D>& u) {
  reactDiffuse(dt);
  advect(dt, u);
}

template <int D>
void ARDSolver<D>::reactDiffuse(double dt) {
  const double t0 = traceClock();
  Stages stages{*this};
  reactDiffuseChemicals(stages, mode_, rdTimeScale_, dt);
  stageSeconds_[0] = traceClock() - t0;
}

template <int D>
void ARDSolver<D>::advect(double dt, const MacVelocity<D>& u) {
  if (tracedAhead_) throw std::logic_error("ARDSolver: the feet were traced ahead; advect(dt) carries to them");
  const double t0 = traceClock();
  Stages stages{*this, &u};
  advectChemicals(stages, mode_, dt);
  stageSeconds_[1] = traceClock() - t0;
  time_ += dt;
  ++steps_;
}

template <int D>
void ARDSolver<D>::traceAhead(double dt, const MacVelocity<D>& u) {
  const double t0 = traceClock();
  if (mode_ != CouplingMode::RDOnly) advector_.trace(u, dt, pool_);  // (advectChemicals' condition)
  tracedAhead_ = true;
  traceSeconds_ = traceClock() - t0;
}

template <int D>
void ARDSolver<D>::advect(double dt) {
  if (!tracedAhead_) throw std::logic_error("ARDSolver: advect(dt) needs traceAhead first");
  const double t0 = traceClock();
  Stages stages{*this};
  advectChemicals(stages, mode_, dt);
  tracedAhead_ = false;
  stageSeconds_[1] = traceSeconds_ + (traceClock() - t0);
  time_ += dt;
  ++steps_;
}

template class ARDSolver<2>;
template class ARDSolver<3>;

}  // namespace morphoflow
