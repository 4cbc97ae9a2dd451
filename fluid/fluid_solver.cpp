#include "fluid/fluid_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "fluid/advection.h"
#include "fluid/extrapolation.h"
#include "fluid/fluid_step.h"
#include "fluid/forces.h"
#include "fluid/obstacle.h"
#include "fluid/obstacle_motion.h"
#include "fluid/smoke.h"

namespace morphoflow {

namespace {
template <int D>
IVec<D> cellsOf(const FluidSettings& s) {
  if (int(s.resolution.size()) != D || int(s.size.size()) != D)
    throw std::invalid_argument("resolution and size must have " + std::to_string(D) + " entries");
  IVec<D> n;
  for (int a = 0; a < D; ++a) {
    if (s.resolution[size_t(a)] < 2) throw std::invalid_argument("resolution must be at least 2 cells per axis");
    n[a] = s.resolution[size_t(a)];
  }
  return n;
}
template <int D>
double cellSize(const FluidSettings& s, const IVec<D>& n) {
  double h = s.size[0] / n[0];
  for (int a = 1; a < D; ++a) {
    double ha = s.size[size_t(a)] / n[a];
    if (std::abs(ha - h) > 1e-6 * h)
      throw std::invalid_argument("cells must be square/cubic: size / resolution must agree on every axis");
  }
  return h;
}
}  // namespace

template <int D>
FluidSolver<D>::FluidSolver(const FluidSettings& s)
    : settings_(s), cells_(cellsOf<D>(s)), h_(cellSize<D>(s, cells_)) {
  for (int a = 0; a < D; ++a) {
    bool lo = s.boundaries.side(a, false).kind == BoundaryKind::Periodic;
    bool hi = s.boundaries.side(a, true).kind == BoundaryKind::Periodic;
    if (lo != hi) throw std::invalid_argument("a periodic axis must be periodic on both sides");
  }
  placement_ = ObstaclePlacement<D>(s, cells_, h_);
  moves_ = placement_.moves();
  constraints_ = placement_.constraintsAt(0.0);
  SolverOptions p{s.pressureTolerance, s.pressureMaxIterations};
  projection_ = std::make_unique<PressureProjection<D>>(constraints_, s.pressureSolver, p);
  viscosity_ = std::make_unique<ViscositySolver<D>>(constraints_, SolverOptions{s.viscosityTolerance, 500});
  u_ = MacVelocity<D>(cells_, h_, constraints_.periodic());
  scratch_ = u_;  // (its storage to the pool: the advection lends it, releaseAdvectedVelocity takes it back)
  for (int a = 0; a < D; ++a) pool_.give(&scratch_[a].values());
  constraints_.apply(&u_);
  if (s.smoke.enabled) {
    temperature_ = Grid<float, D>(cells_, float(s.smoke.ambient));
    sourceCoverage_ = sourceCoverage<D>(s.smoke.sources, cells_, h_, constraints_.solid);
    if (!s.smoke.sources.empty()) materialisedDye();
  }
}

// Moving obstacles (fluid/obstacle_motion.h): the constraints, pressure
// and viscous systems at time t. With `fill`, the cells and faces the
// solid uncovers take the mean of their fluid neighbours (repeated
// outward). Those it covers keep their smoke and temperature, which the
// solid's velocity then carries with it: the fluid pushed ahead of the
// solid traces back into them and takes them along, so that nothing is
// lost at a moving wall (a closed box stirred by a paddle keeps its dye to
// 0.2% a turn: tests/fluid/test_moving_obstacles.cpp). Their faces take the
// solid's velocity.
template <int D>
void FluidSolver<D>::placeObstacles(double t, bool fill) {
  if (!moves_) return;
  IVec<D> lo, hi;
  if (!placement_.moveTo(t, &constraints_, &lo, &hi)) return;
  // The pressure's and the viscosity's systems follow at once (each its own; an inviscid fluid never solves the
  // latter).
  parallelTasks(settings_.viscosity > 0 ? 2 : 1, [&](size_t k) {
    if (k == 0) projection_->rebuild(lo, hi);
    else viscosity_->rebuild(lo, hi);
  });
  cutSurfaceMade_ = false;
  if (!fill) return;
  parallelTasks(size_t(1 + D), [&](size_t k) {  // (the cells' plan, and each face grid's: their own)
    const int a = int(k) - 1;
    if (a >= 0) {
      applyFill<float>(placement_.faceFill(constraints_, a), u_[a].data(), std::nullopt);
      return;
    }
    const FillPlan cells = placement_.cellFill(constraints_);
    if (!dye_.empty()) applyFill<float>(cells, dye_.data(), std::nullopt);
    if (!temperature_.empty()) applyFill<float>(cells, temperature_.data(), std::nullopt);
  });
  constraints_.apply(&u_);
}

// The CPU's stages of the fluid step, whose order is fluid/fluid_step.h's.
template <int D>
struct FluidSolver<D>::Stages {
  using Clock = std::chrono::steady_clock;
  FluidSolver& f;
  Clock::time_point t0{};

  void mark(int stage) {
    const Clock::time_point t1 = Clock::now();
    if (stage > 0) f.stats_.seconds[size_t(stage - 1)] = std::chrono::duration<double>(t1 - t0).count();
    t0 = t1;
  }
  void resumeClock() { t0 = Clock::now(); }
  bool smoke() const { return f.settings_.smoke.enabled; }
  void emitSmoke(double dt) {
    morphoflow::emitSmoke<D>(f.settings_.smoke, f.sourceCoverage_, f.constraints_.solid, f.time_, dt, &f.dye(),
                             &f.temperature_, &f.u_);
  }
  void forces(double dt) { applyForces<D>(f.settings_, f.dye_.empty() ? nullptr : &f.dye_, dt, &f.u_); }
  void smokeForces(double dt) {
    applySmokeForces<D>(f.settings_.smoke, f.settings_.buoyancyDirection, f.dye(), f.temperature_, dt, &f.u_, &f.pool_);
  }
  void constrain() { f.constraints_.apply(&f.u_); }
  void advect(double dt) {
    size_t largest = 0;  // (a face grid: the scalars' cell grids are smaller)
    for (int a = 0; a < D; ++a) {
      f.pool_.lend(&f.scratch_[a].values(), f.u_[a].size());  // (kept where keepAdvectedVelocity asked)
      f.scratch_[a].reshape(f.u_[a].dims());
      largest = std::max(largest, f.u_[a].size());
    }
    f.advectionScratch_.borrow(&f.pool_, f.settings_.advection, largest);
    advectVelocity<D>(f.u_, dt, f.settings_.advection, &f.scratch_, &f.advectionScratch_);
    // An all-zero dye (no dye in the scene yet) advects to zero: skip the work.
    const Grid<float, D>& dye = f.dye_;
    const bool dyed =
        !dye.empty() && std::any_of(dye.values().begin(), dye.values().end(), [](float v) { return v != 0.0f; });
    if (dyed || !f.temperature_.empty()) {
      // The scalars skip the rows of empty space (fluid/advection.h).
      const std::optional<std::array<int, D>> reach = traceReach<D>(f.u_, dt);
      if (dyed) f.advectScalar(&f.dye_, dt, reach);
      if (!f.temperature_.empty()) f.advectScalar(&f.temperature_, dt, reach);
    }
    f.advectionScratch_.giveBack(&f.pool_);
    std::swap(f.u_, f.scratch_);  // scratch_ keeps the velocity advected through (advectedVelocity())
  }
  void releaseAdvected() { f.releaseAdvectedVelocity(); }
  void injectInflowDye() { f.injectInflowDye(); }
  void decaySmoke(double dt) { morphoflow::decaySmoke<D>(f.settings_.smoke, dt, &f.dye(), &f.temperature_); }
  void diffuse(double dt) {
    f.stats_.viscosity = f.viscosity_->diffuse(&f.u_, f.settings_.viscosity, dt, &f.pool_);
    f.stats_.viscosityCellUpdates = f.viscosity_->lastCellUpdates();
    f.stats_.viscosityUsedCG = f.viscosity_->lastUsedCG();
  }
  void project(double dt) { f.stats_.pressure = f.projection_->project(&f.u_, dt, f.settings_.density, &f.pool_); }
  void advanceClock(double dt) {
    f.time_ += dt;
    ++f.steps_;
  }
};

template <int D>
void FluidSolver<D>::step(double dt, const std::function<void()>& afterAdvection) {
  // The solid where the step ends, which the projection meets.
  if (moves_ && placement_.time() != time_ + dt) placeObstacles(time_ + dt, true);
  Stages stages{*this};
  stepFluid(stages, dt, afterAdvection);
}

template <int D>
void FluidSolver<D>::releaseAdvectedVelocity() {
  if (keepsAdvected_) return;
  for (int a = 0; a < D; ++a) pool_.give(&scratch_[a].values());
}

// A cell-centred scalar carried through u_ (before the swap) with the
// fluid's advection scheme, through a work grid lent only for it; with
// reach, rows of empty space are written without tracing.
template <int D>
void FluidSolver<D>::advectScalar(Grid<float, D>* field, double dt, const std::optional<std::array<int, D>>& reach) {
  pool_.lend(&dyeScratch_.values());
  dyeScratch_.reshape(cells_);
  advectField<D>(*field, cellLayout(), u_, dt, settings_.advection, &dyeScratch_, &advectionScratch_,
                 reach ? &*reach : nullptr);
  std::swap(*field, dyeScratch_);
  pool_.give(&dyeScratch_.values());
}

template <int D>
void FluidSolver<D>::injectInflowDye() {
  const int stripes = settings_.inflowDyeStripes;
  if (stripes <= 0) return;
  for (int a = 0; a < D; ++a)
    for (bool high : {false, true}) {
      if (settings_.boundaries.side(a, high).kind != BoundaryKind::Inflow) continue;
      // Stripes alternate along the first transverse axis of the inflow side.
      int across = a == 0 ? 1 : 0;
      forEachCell<D>(cells_, [&](const IVec<D>& k, size_t i) {
        if (k[a] != (high ? cells_[a] - 1 : 0) || constraints_.solid[i]) return;
        int band = int(std::floor(double(k[across]) / cells_[across] * 2 * stripes));
        dye()[i] = band % 2 == 0 ? 1.0f : 0.0f;
      });
    }
}

template <int D>
double FluidSolver<D>::maxSpeed() const {
  double m2 = 0.0;
  for (int a = 0; a < D; ++a) {
    const Grid<float, D>& g = u_[a];
    m2 = std::max(m2, deterministicMax(g.size(), [&](size_t i) { return std::abs(double(g[i])); }));
  }
  // Bound of the speed from the largest component magnitude.
  return std::sqrt(double(D)) * m2;
}

template <int D>
double FluidSolver<D>::cflTimeStep(double cfl, double dtMax) const {
  double umax = maxSpeed();
  for (const ObstacleSpec& o : settings_.obstacles) umax = std::max(umax, obstacleSpeedBound(o, D, time_));
  if (umax <= 0) return dtMax;
  return std::min(dtMax, cfl * h_ / umax);
}

template <int D>
void FluidSolver<D>::save(StateWriter* out) const {
  for (int a = 0; a < D; ++a) out->putGrid("fluid.u" + std::to_string(a), u_[a]);
  if (!dye_.empty()) out->putGrid("fluid.dye", dye_);
  if (!temperature_.empty()) out->putGrid("fluid.temperature", temperature_);
  out->put("fluid.time", time_);
  out->put("fluid.steps", steps_);
  projection_->save(out);
  viscosity_->save(out);
}

template <int D>
void FluidSolver<D>::load(const StateReader& in) {
  for (int a = 0; a < D; ++a) in.getGrid("fluid.u" + std::to_string(a), &u_[a]);
  dye_ = Grid<float, D>();
  if (in.has("fluid.dye")) in.getGrid("fluid.dye", &dye());
  if (!temperature_.empty()) in.getGrid("fluid.temperature", &temperature_);
  in.get("fluid.time", &time_);
  in.get("fluid.steps", &steps_);
  placeObstacles(time_, false);
  projection_->load(in);
  viscosity_->load(in);
}

template <int D>
void FluidSolver<D>::adopt(double time, long steps, const std::vector<double>& phi, double dt) {
  if (moves_ && placement_.time() != time) placeObstacles(time, false);  // (the probes meet the solid there)
  time_ = time;
  steps_ = steps;
  projection_->adopt(phi, dt, settings_.density);
}

template class FluidSolver<2>;
template class FluidSolver<3>;

}  // namespace morphoflow
