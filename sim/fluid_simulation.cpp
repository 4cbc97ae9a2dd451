#include "sim/fluid_simulation.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "sim/steppers.h"
#include "core/parallel.h"
#include "fluid/probes.h"
#include "fluid/smoke.h"

namespace morphoflow {

template <int D>
void initialiseDye(const Scene& scene, FluidSolver<D>* f) {
  if (scene.dye.initial == "none") return;
  const int n = scene.dye.stripes;
  Grid<float, D>& dye = f->dye();
  const IVec<D>& cells = f->cells();
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    int bx = int(std::floor(double(k[0]) / cells[0] * n));
    int by = int(std::floor(double(k[1]) / cells[1] * n));
    bool on = scene.dye.initial == "stripes" ? bx % 2 == 0 : (bx + by) % 2 == 0;
    dye[i] = on && !f->solid()[i] ? 1.0f : 0.0f;
  });
}

template <int D>
std::vector<Grid<float, D>> fluidField(const FluidSolver<D>& f, const std::string& name) {
  if (name == fields::kSpeed) return {speedField(f)};
  if (name == fields::kVorticity) return {vorticityField(f)};
  if (name == fields::kDye) return {f.dye()};
  if (name == fields::kTemperature)  // (without [smoke]: 0 everywhere)
    return {f.temperature().empty() ? Grid<float, D>(f.cells(), 0.0f) : f.temperature()};
  if (name == fields::kPressure) return {f.pressure()};
  if (name == fields::kObstacle) {
    Grid<float, D> s(f.cells(), 0.0f);
    for (size_t i = 0; i < s.size(); ++i) s[i] = f.solid()[i] ? 1.0f : 0.0f;
    return {s};
  }
  if (name == fields::kVelocity) {
    std::vector<Grid<float, D>> v(static_cast<size_t>(D), Grid<float, D>(f.cells(), 0.0f));
    forEachCell<D>(f.cells(), [&](const IVec<D>& k, size_t i) {
      const Vec<D> u = f.velocity().atCell(k);
      for (int a = 0; a < D; ++a) v[size_t(a)][i] = float(u[a]);
    });
    return v;
  }
  if (name == fields::kVelocityMac) {  // component a on the faces normal to a, padded to cells + 1 per axis (zeros)
    std::vector<Grid<float, D>> v(static_cast<size_t>(D), Grid<float, D>(f.cells() + IVec<D>(1), 0.0f));
    for (int a = 0; a < D; ++a) {
      const Grid<float, D>& u = f.velocity()[a];
      for (size_t i = 0; i < u.size(); ++i) v[size_t(a)](u.coord(i)) = u[i];
    }
    return v;
  }
  throw std::invalid_argument("no fluid field '" + name + "'");
}

template <int D>
FluidSimulation<D>::FluidSimulation(const Scene& scene, Backend backend, Warn warn)
    : scene_(scene), warn_(std::move(warn)), fluid_(scene.fluid), host_([this] { stepper_->toHost(&fluid_); }) {
  checkFluidLeft<D>(scene, fluid_);
  warnOfEmptySources<D>(scene, fluid_, warn_);
  initialiseDye<D>(scene, &fluid_);
  stepper_ = makeFluidStepper<D>(scene, backend, &fluid_);  // from the state set up here
  for (int a = 0; a < D; ++a)
    for (bool hi : {false, true})
      if (scene.fluid.boundaries.side(a, hi).kind == BoundaryKind::Inflow) flowAxis_ = a;
  // A towed body (no inflow, the first obstacle moving): the drag opposes its motion at the start.
  const std::vector<ObstacleSpec>& obstacles = scene.fluid.obstacles;
  if (flowAxis_ < 0 && !obstacles.empty() && movesAtAll(obstacles.front())) {
    RigidMotion m;
    placedAt(obstacles.front(), D, scene.timeline.obstacles.front().start, &m);
    flowAxis_ = 0;
    for (int a = 1; a < D; ++a)
      if (std::abs(m.velocity[size_t(a)]) > std::abs(m.velocity[size_t(flowAxis_)])) flowAxis_ = a;
    if (m.velocity[size_t(flowAxis_)] > 0.0) dragSign_ = -1.0;
  }
  if (flowAxis_ < 0) flowAxis_ = 0;
  liftAxis_ = flowAxis_ == 1 ? 0 : 1;
}

template <int D>
double FluidSimulation<D>::cflTimeStep(double cfl, double dtMax) const {
  return stepper_->cflTimeStep(cfl, dtMax);
}

template <int D>
void FluidSimulation<D>::step(double dt) {
  stepper_->step(dt);
  host_.stepped();
  const FluidStepStats& st = stepper_->lastStats();
  for (int k = 0; k < FluidStepStats::kStages; ++k) stageTotals_[size_t(k)] += st.seconds[size_t(k)];
  pressureIterations_ += st.pressure.iterations;
  viscosityIterations_ += st.viscosity.iterations;
  maxPressureIterations_ = std::max(maxPressureIterations_, st.pressure.iterations);
  maxPressureResidual_ = std::max(maxPressureResidual_, st.pressure.residual);
  if (!st.pressure.converged && unconverged_++ == 0)
    warn_(fmt::format("warning: step {}: pressure solve stopped at relative residual {:.2e} after {} iterations",
                      steps(), st.pressure.residual, st.pressure.iterations));
  if (!stepper_->finite())
    throw NonFiniteError(
        fmt::format("the simulation diverged at step {} in the fluid step: the velocity is not finite", steps()),
        "use a smaller time.dt or set time.cfl, and check the forces and boundary speeds");
  if (scene_.probes.forces) {
    const ProbeSettings& pr = scene_.probes;
    const double q = 0.5 * scene_.fluid.density * pr.referenceSpeed * pr.referenceSpeed * pr.referenceArea;
    host_.refresh();
    const auto F = obstacleForce<D>(fluid_);
    forceTime_.push_back(time());
    drag_.push_back(dragSign_ * F[size_t(flowAxis_)] / q);
    lift_.push_back(F[size_t(liftAxis_)] / q);
  }
}

template <int D>
void FluidSimulation<D>::save(StateWriter* out) const {
  host_.refresh();
  fluid_.save(out);
  stepper_->save(out);
  out->put("fluid.stats.stage_totals", stageTotals_);
  out->put("fluid.stats.pressure_iterations", pressureIterations_);
  out->put("fluid.stats.viscosity_iterations", viscosityIterations_);
  out->put("fluid.stats.pressure_iterations_max", maxPressureIterations_);
  out->put("fluid.stats.unconverged", unconverged_);
  out->put("fluid.stats.pressure_residual_max", maxPressureResidual_);
  out->putVector("fluid.probe.force_time", forceTime_);
  out->putVector("fluid.probe.drag", drag_);
  out->putVector("fluid.probe.lift", lift_);
}

template <int D>
void FluidSimulation<D>::load(const StateReader& in) {
  fluid_.load(in);
  stepper_->fromHost(fluid_);
  stepper_->load(in);
  in.get("fluid.stats.stage_totals", &stageTotals_);
  in.get("fluid.stats.pressure_iterations", &pressureIterations_);
  in.get("fluid.stats.viscosity_iterations", &viscosityIterations_);
  in.get("fluid.stats.pressure_iterations_max", &maxPressureIterations_);
  in.get("fluid.stats.unconverged", &unconverged_);
  in.get("fluid.stats.pressure_residual_max", &maxPressureResidual_);
  const size_t n = scene_.probes.forces ? size_t(steps()) : 0;
  forceTime_.resize(n);
  drag_.resize(n);
  lift_.resize(n);
  in.getVector("fluid.probe.force_time", &forceTime_);
  in.getVector("fluid.probe.drag", &drag_);
  in.getVector("fluid.probe.lift", &lift_);
}

template <int D>
nlohmann::json FluidSimulation<D>::resolved() const {
  const ProbeSettings& pr = scene_.probes;
  return {{"dimension", D},
          {"resolution", scene_.fluid.resolution},
          {"size", scene_.fluid.size},
          {"cell_size", fluid_.h()},
          {"viscosity", scene_.fluid.viscosity},
          {"reynolds", scene_.reynolds},
          {"reference_length", pr.referenceLength},
          {"reference_speed", pr.referenceSpeed},
          {"dt", scene_.time.dt},
          {"cfl", scene_.time.cfl}};
}

template <int D>
void FluidSimulation<D>::report(nlohmann::json* j) const {
  const double steps = double(this->steps());
  stepper_->report(j);
  nlohmann::json stages;
  for (int k = 0; k < FluidStepStats::kStages; ++k)
    stages[FluidStepStats::kStageNames[k]] = {{"total_seconds", stageTotals_[size_t(k)]},
                                              {"ms_per_step", steps ? 1e3 * stageTotals_[size_t(k)] / steps : 0.0}};
  (*j)["stages"] = stages;
  (*j)["solvers"] = {{"pressure_iterations_mean", steps ? double(pressureIterations_) / steps : 0.0},
                     {"pressure_iterations_max", maxPressureIterations_},
                     {"pressure_residual_max", maxPressureResidual_},
                     {"pressure_unconverged_steps", unconverged_},
                     {"viscosity_iterations_mean", steps ? double(viscosityIterations_) / steps : 0.0}};
  const ProbeSettings& pr = scene_.probes;
  if (!pr.forces) return;
  const double start = pr.strouhalStart >= 0 ? pr.strouhalStart : 0.5 * time();
  // A moving body's lift, over the time it takes to cross a cell (fluid/probes.h).
  const std::vector<double> lift =
      fluid_.movesObstacles() ? windowMean(forceTime_, lift_, fluid_.h() / pr.referenceSpeed) : lift_;
  const StrouhalEstimate st = estimateStrouhal(forceTime_, lift, start, pr.referenceLength, pr.referenceSpeed);
  double cdMean = 0, clMean = 0;
  int n = 0;
  for (size_t i = 0; i < drag_.size(); ++i)
    if (forceTime_[i] >= start) {
      cdMean += drag_[i];
      clMean += lift_[i];
      ++n;
    }
  (*j)["strouhal"] = st.periods > 0 ? nlohmann::json(st.strouhal) : nlohmann::json(nullptr);
  (*j)["lift"] = {{"periods", st.periods},
                  {"period_spread", st.periodSpread},
                  {"period_strouhal", st.periodStrouhal},
                  {"measured_from_time", start}};
  (*j)["drag_coefficient_mean"] = n ? cdMean / n : 0.0;
  (*j)["lift_coefficient_mean"] = n ? clMean / n : 0.0;
}

namespace {

std::string profileCsv(const Profile& p) {
  std::string s = "coord,value\n";
  for (size_t i = 0; i < p.coord.size(); ++i) s += fmt::format("{:.6f},{:.6f}\n", p.coord[i], p.value[i]);
  return s;
}

}  // namespace

template <int D>
std::vector<std::pair<std::string, std::string>> FluidSimulation<D>::measurementFiles() const {
  host_.refresh();
  std::vector<std::pair<std::string, std::string>> files;
  const ProbeSettings& pr = scene_.probes;
  if (pr.centerlines) {
    // Vertical centreline: u along y; horizontal centreline: v along x.
    files.push_back(
        {"profiles/u_vertical_centerline.csv", profileCsv(centerlineProfile<D>(fluid_, 0, 1, pr.referenceSpeed))});
    files.push_back(
        {"profiles/v_horizontal_centerline.csv", profileCsv(centerlineProfile<D>(fluid_, 1, 0, pr.referenceSpeed))});
  }
  if (pr.forces) {
    std::string csv = "step,time,drag_coefficient,lift_coefficient\n";
    for (size_t i = 0; i < forceTime_.size(); ++i)
      csv += fmt::format("{},{:.6f},{:.6f},{:.6f}\n", i + 1, forceTime_[i], drag_[i], lift_[i]);
    files.push_back({"forces.csv", csv});
  }
  return files;
}

template <int D>
void checkFluidLeft(const Scene& scene, const FluidSolver<D>& fluid) {
  const Grid<uint8_t, D>& solid = fluid.solid();
  if (std::all_of(solid.values().begin(), solid.values().end(), [](uint8_t s) { return s != 0; }))
    throw UserError({scene.path, 0, 0}, "obstacles", "the obstacles cover every cell: no fluid is left to simulate",
                    "make the obstacles smaller than the domain");
  // An inflow side whose every cell is solid lets nothing in.
  for (int a = 0; a < D; ++a)
    for (bool high : {false, true}) {
      if (scene.fluid.boundaries.side(a, high).kind != BoundaryKind::Inflow) continue;
      bool open = false;
      for (size_t i = 0; i < solid.size() && !open; ++i) {
        const IVec<D> c = solid.coord(i);
        open = c[a] == (high ? solid.dims()[a] - 1 : 0) && !solid[i];
      }
      if (!open)
        throw UserError({scene.path, 0, 0}, "obstacles",
                        fmt::format("the obstacles cover the whole inflow side ({} {}): no fluid can enter",
                                    high ? "high" : "low", "xyz"[a]),
                        "move or shrink the obstacles so that part of the inflow is open");
    }
}

// An obstacle the grid does not see, and a fixed source that covers no
// fluid cell (smaller than the samples of a cell, inside an obstacle, an
// image or sdf with nothing inside) and so emits nothing: said, as a source
// whose window opens after the run is.
// Whether an obstacle meets the grid: it holds a cell's centre, or (cut
// boundary) its surface crosses a face plane, so that some face is partly closed.
template <int D>
bool meetsGrid(const ObstacleSpec& o, const IVec<D>& cells, double h) {
  const Grid<uint8_t, D> solid = solidMask<D>({o}, cells, h);
  if (std::any_of(solid.values().begin(), solid.values().end(), [](uint8_t v) { return v != 0; })) return true;
  if (o.boundary == ObstacleBoundary::Voxel) return false;
  if (o.shape == ObstacleShape::Circle && D == 3) return true;  // (a cylinder along z crosses every z face)
  const bool round = o.shape == ObstacleShape::Circle || o.shape == ObstacleShape::Sphere;
  if (!round && o.shape != ObstacleShape::Box) return true;  // (an image or sdf: its cells decide; none here is rare)
  for (int a = 0; a < D; ++a) {
    const double reach = round ? o.radius : o.halfSize[size_t(a)];
    if (std::floor((o.center[size_t(a)] + reach) / h) != std::floor((o.center[size_t(a)] - reach) / h)) return true;
  }
  return false;
}

template <int D>
void warnOfEmptySources(const Scene& scene, const FluidSolver<D>& fluid,
                        const std::function<void(const std::string&)>& warn) {
  const std::vector<ObstacleSpec>& obstacles = scene.fluid.obstacles;
  for (size_t q = 0; q < obstacles.size() && warn; ++q)
    if (!movesAtAll(obstacles[q]) &&
        !meetsGrid<D>(obstacles[q], fluid.cells(), fluid.h()))  // (a moving one may come in)
      warn(fmt::format("warning: obstacles.{} meets no cell centre or face of the grid (it lies between the faces of "
                       "one cell): the flow does not see it, and its drag and lift are 0; make it larger than a cell "
                       "or refine grid.resolution",
                       q));
  const std::vector<SmokeSource>& sources = scene.fluid.smoke.sources;
  for (size_t q = 0; q < sources.size(); ++q) {
    if (!sources[q].motion.empty()) continue;  // (a moving one may come into the fluid)
    const Grid<float, D> cover = sourceCover<D>(sources[q], sources[q].start, fluid.cells(), fluid.h(), fluid.solid());
    if (std::all_of(cover.values().begin(), cover.values().end(), [](float c) { return c == 0.0f; }) && warn)
      warn(fmt::format("warning: sources.{} covers no fluid cell (smaller than a cell, inside an obstacle, or an image "
                       "or sdf with nothing inside): it emits nothing",
                       q));
  }
}

template <int D>
void checkFluidBounded(const FluidSolver<D>& fluid, const std::string& where);

template <int D>
void checkFluidFinite(const FluidSolver<D>& fluid, const std::string& where) {
  auto finite = [](const Grid<float, D>& g) {
    for (float v : g.values())
      if (!std::isfinite(v)) return false;
    return true;
  };
  for (int a = 0; a < D; ++a)
    if (!finite(fluid.velocity()[a]))
      throw NonFiniteError(
          fmt::format("the simulation diverged {} in the fluid step: velocity component {} is not finite", where,
                      "xyz"[a]),
          "use a smaller time.dt or set time.cfl, and check the forces and boundary speeds");
  if (fluid.hasDye() && !finite(fluid.dye()))
    throw NonFiniteError(fmt::format("the simulation diverged {} in the fluid step: the dye is not finite", where),
                         "use a smaller time.dt or set time.cfl");
  checkFluidBounded<D>(fluid, where);
}

// A run that blew up while staying finite: a speed of more than 1000 domain
// lengths per unit time and 1000 times the fastest speed the scene gives
// (walls, inflow, sources), which no scene means. The hint names the forces
// the scene sets, the likeliest causes.
template <int D>
void checkFluidBounded(const FluidSolver<D>& fluid, const std::string& where) {
  const FluidSettings& f = fluid.settings();
  double given = 0.0;
  for (const DomainSide& side : f.boundaries.sides) {
    for (double w : side.wallVelocity) given = std::max(given, std::abs(w));
    if (side.kind == BoundaryKind::Inflow) given = std::max(given, 1.5 * std::abs(f.boundaries.inflowMeanVelocity));
  }
  for (const SmokeSource& src : f.smoke.sources)
    for (double v : src.velocity) given = std::max(given, std::abs(v));
  const double length = *std::max_element(f.size.begin(), f.size.end()), bound = 1e3 * std::max(length, given);
  double top = 0.0;
  for (int a = 0; a < D; ++a)
    for (float v : fluid.velocity()[a].values()) top = std::max(top, double(std::abs(v)));
  if (top <= bound) return;
  std::vector<std::string> forces;
  auto say = [&](const char* key, double v) {
    if (v != 0.0) forces.push_back(fmt::format("{} = {:g}", key, v));
  };
  say("smoke.vorticity", f.smoke.vorticity);
  say("smoke.buoyancy", f.smoke.heat);
  say("smoke.weight", f.smoke.weight);
  say("fluid.buoyancy", f.buoyancy);
  for (int a = 0; a < D; ++a)
    say(a == 0 ? "fluid.force[0]" : a == 1 ? "fluid.force[1]" : "fluid.force[2]", f.force[size_t(a)]);
  throw NonFiniteError(
      fmt::format(
          "the simulation blew up {} in the fluid step: the speed reached {:.3g}, more than 1000 domain lengths "
          "and 1000 times the scene's speeds ({:g} in all) per unit time",
          where, top, bound),
      forces.empty() ? std::string("use a smaller time.dt or set time.cfl, and check the boundary speeds")
                     : fmt::format("the forces set, the likeliest causes: {}; lower them, or use a smaller time.dt",
                                   fmt::join(forces, ", ")));
}

template void checkFluidFinite<2>(const FluidSolver<2>&, const std::string&);
template void checkFluidFinite<3>(const FluidSolver<3>&, const std::string&);
template void warnOfEmptySources<2>(const Scene&, const FluidSolver<2>&,
                                    const std::function<void(const std::string&)>&);
template void warnOfEmptySources<3>(const Scene&, const FluidSolver<3>&,
                                    const std::function<void(const std::string&)>&);
template void checkFluidLeft<2>(const Scene&, const FluidSolver<2>&);
template void checkFluidLeft<3>(const Scene&, const FluidSolver<3>&);
template void initialiseDye<2>(const Scene&, FluidSolver<2>*);
template void initialiseDye<3>(const Scene&, FluidSolver<3>*);
template <int D>
bool setFluidField(FluidSolver<D>* fluid, const std::string& name, const Grid<float, D>& values) {
  const bool temperature = name == fields::kTemperature && !fluid->temperature().empty();
  if (name != fields::kDye && !temperature) return false;
  Grid<float, D>& g = temperature ? fluid->temperature() : fluid->dye();
  if (values.dims() != g.dims())
    throw UserError({"set_field", 0, 0}, "", "the values of '" + name + "' are not on its grid",
                    "give field()'s shape");
  for (size_t i = 0; i < g.size(); ++i)
    if (!std::isnan(values[i])) g[i] = values[i];  // (NaN: the cell keeps its value)
  return true;
}

template bool setFluidField<2>(FluidSolver<2>*, const std::string&, const Grid<float, 2>&);
template bool setFluidField<3>(FluidSolver<3>*, const std::string&, const Grid<float, 3>&);
template std::vector<Grid<float, 2>> fluidField<2>(const FluidSolver<2>&, const std::string&);
template std::vector<Grid<float, 3>> fluidField<3>(const FluidSolver<3>&, const std::string&);
template class FluidSimulation<2>;
template class FluidSimulation<3>;

}  // namespace morphoflow
