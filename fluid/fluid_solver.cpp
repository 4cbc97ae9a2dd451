#include "fluid/fluid_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "fluid/advection.h"
#include "fluid/forces.h"
#include "fluid/obstacle.h"
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
  std::vector<ObstacleSpec> voxel;  // the staircase obstacles; the others are cut
  for (const ObstacleSpec& o : s.obstacles)
    if (o.boundary == ObstacleBoundary::Voxel) voxel.push_back(o);
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells_[a] * h_;
  constraints_ = VelocityConstraints<D>(cells_, h_, s.boundaries, solidMask<D>(s.obstacles, cells_, h_),
                                        solidMask<D>(voxel, cells_, h_), CutSurface(s.obstacles, D, size));
  SolverOptions p{s.pressureTolerance, s.pressureMaxIterations};
  projection_ = std::make_unique<PressureProjection<D>>(constraints_, s.pressureSolver, p);
  viscosity_ = std::make_unique<ViscositySolver<D>>(constraints_, SolverOptions{s.viscosityTolerance, 500});
  u_ = MacVelocity<D>(cells_, h_, constraints_.periodic());
  scratch_ = u_;
  constraints_.apply(&u_);
  if (s.smoke.enabled) {
    temperature_ = Grid<float, D>(cells_, float(s.smoke.ambient));
    sourceCoverage_ = sourceCoverage<D>(s.smoke.sources, cells_, h_, constraints_.solid);
    if (!s.smoke.sources.empty()) materialisedDye();
  }
}

template <int D>
void FluidSolver<D>::step(double dt, const std::function<void()>& afterAdvection) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  auto lap = [&](int stage) {
    auto t1 = Clock::now();
    stats_.seconds[size_t(stage)] = std::chrono::duration<double>(t1 - t0).count();
    t0 = t1;
  };
  // 1. forces (with [smoke]: the sources' emission, buoyancy, confinement)
  const SmokeSettings& smoke = settings_.smoke;
  if (smoke.enabled) emitSmoke<D>(smoke, sourceCoverage_, constraints_.solid, time_, dt, &dye(), &temperature_, &u_);
  applyForces<D>(settings_, dye_.empty() ? nullptr : &dye_, dt, &u_);
  if (smoke.enabled) applySmokeForces<D>(smoke, settings_.buoyancyDirection, dye(), temperature_, dt, &u_, &pool_);
  constraints_.apply(&u_);
  lap(0);
  // 2. advect (velocity through itself, dye and temperature through the same field)
  advectionScratch_.borrow(&pool_, settings_.advection);
  advectVelocity<D>(u_, dt, settings_.advection, &scratch_, &advectionScratch_);
  // An all-zero dye (no dye in the scene yet) advects to zero: skip the work.
  const bool dyed =
      !dye_.empty() && std::any_of(dye_.values().begin(), dye_.values().end(), [](float v) { return v != 0.0f; });
  if (dyed || !temperature_.empty()) {
    // The scalars skip the rows of empty space (fluid/advection.h).
    const std::optional<std::array<int, D>> reach = traceReach<D>(u_, dt);
    if (dyed) advectScalar(&dye_, dt, reach);
    if (!temperature_.empty()) advectScalar(&temperature_, dt, reach);
  }
  advectionScratch_.giveBack(&pool_);
  std::swap(u_, scratch_);  // scratch_ keeps the velocity advected through (advectedVelocity())
  constraints_.apply(&u_);
  injectInflowDye();
  if (smoke.enabled) decaySmoke<D>(smoke, dt, &dye(), &temperature_);
  lap(1);
  if (afterAdvection) afterAdvection();
  // 3. diffuse (implicit viscosity)
  stats_.viscosity = viscosity_->diffuse(&u_, settings_.viscosity, dt, &pool_);
  stats_.viscosityCellUpdates = viscosity_->lastCellUpdates();
  stats_.viscosityUsedCG = viscosity_->lastUsedCG();
  lap(2);
  // 4. project
  stats_.pressure = projection_->project(&u_, dt, settings_.density, &pool_);
  lap(3);
  time_ += dt;
  ++steps_;
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
  projection_->load(in);
  viscosity_->load(in);
}

template <int D>
void FluidSolver<D>::adopt(double time, long steps, const std::vector<double>& phi, double dt) {
  time_ = time;
  steps_ = steps;
  projection_->adopt(phi, dt, settings_.density);
}

template class FluidSolver<2>;
template class FluidSolver<3>;

}  // namespace morphoflow
