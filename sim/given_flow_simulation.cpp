#include "sim/given_flow_simulation.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "sim/rd_scene_setup.h"
#include "core/error.h"
#include "core/parallel.h"
#include "rd/model_registry.h"

namespace morphoflow {

namespace {

template <int D>
std::unique_ptr<GivenVelocity<D>> velocitySource(const VelocityScene& v, const RDSettings& rd) {
  if (!v.field.empty()) return std::make_unique<ExpressionVelocity<D>>(v.field);
  std::array<double, D> domain{};
  for (int a = 0; a < D; ++a) domain[size_t(a)] = rd.size[size_t(a)];
  return std::make_unique<VdbVelocitySequence<D>>(findVelocityFrames(v.vdb, v.frameTime), domain);
}

}  // namespace

template <int D>
GivenFlowSimulation<D>::GivenFlowSimulation(const Scene& scene) : GivenFlowSimulation(scene, nullptr) {}

template <int D>
GivenFlowSimulation<D>::GivenFlowSimulation(const Scene& scene, std::unique_ptr<GivenVelocity<D>> source)
    : scene_(scene), rd_(scene.rd.settings, *findModel(scene.rd.settings.model)) {
  initialState<D>(scene, &rd_);
  applyScene<D>(scene, &rd_);
  // The chemicals' domain: walls (feet clamped) or periodic, as the layer's boundary.
  ChemicalDomain<D> domain;
  domain.cells = rd_.cells();
  domain.h = rd_.h();
  const bool periodic = scene.rd.settings.boundary == RDBoundary::Periodic;
  domain.periodic.fill(periodic);
  const CouplingScene& C = scene.coupling;
  ard_ = std::make_unique<ARDSolver<D>>(
      &rd_, ChemicalAdvector<D>(domain, C.interpolation),
      C.mode, C.rdTimeScale);
  u_ = MacVelocity<D>(rd_.cells(), rd_.h(), domain.periodic);
  if (scene.velocity.python && !source)
    throw UserError(scene.velocity.where, scene.velocity.key,
                    "this scene takes its velocity from Python (python = true)",
                    "run it from the Python module: morphoflow.Simulation(scene).set_velocity(...)");
  try {
    source_ = source ? std::move(source) : velocitySource<D>(scene.velocity, scene.rd.settings);
  } catch (const VelocityFileError& e) {
    throw UserError(scene.velocity.where, scene.velocity.key, e.path() + ": " + e.what());
  }
  if (const DiffusionTensorSpec<D>* t = rd_.diffusionTensorSpec(); t && scene.rd.anisotropy.directionFromVelocity) {
    lambda1_ = t->lambda1;
    lambda2_ = t->lambda2;
  }
  sampleVelocity(0.0);
}

// The velocity at time t; the maps follow it (once for a steady field).
template <int D>
void GivenFlowSimulation<D>::sampleVelocity(double t) {
  if (sampled_ && source_->steady()) return;
  try {
    source_->sample(t, &u_);
  } catch (const VelocityFileError& e) {
    throw UserError(scene_.velocity.where, scene_.velocity.key, e.path() + ": " + e.what(),
                    "every frame of the sequence must be a readable .vdb with a 'vel' grid over the scene's domain");
  }
  checkVelocityFinite(t);
  sampled_ = true;
  applyVelocityMaps();
}

// A velocity from the user (an expression, a VDB file) is finite where it is
// read: a NaN or an infinity would send the chemicals' back-traces anywhere.
template <int D>
void GivenFlowSimulation<D>::checkVelocityFinite(double t) const {
  for (int a = 0; a < D; ++a) {
    const Grid<float, D>& g = u_[a];
    for (size_t i = 0; i < g.size(); ++i) {
      if (std::isfinite(g[i])) continue;
      const IVec<D> k = g.coord(i);
      std::string at = "face (" + std::to_string(k[0]);
      for (int b = 1; b < D; ++b) at += ", " + std::to_string(k[b]);
      const bool fromFile = !scene_.velocity.vdb.empty();
      throw UserError(
          scene_.velocity.where, scene_.velocity.key,
          fmt::format("the given velocity's {} component is {} at {}) at t = {:g}", "uvw"[a],
                      std::isnan(g[i]) ? "NaN" : "infinite", at, t),
          fromFile
              ? "the velocity file holds values that are not finite: write it again from a run that did not diverge"
              : "guard divisions and logarithms, and keep the values within float range (|v| < 3e38)");
    }
  }
}

// The velocity at an RD cell's centre (u_ may be on the source's own grid).
template <int D>
Vec<D> GivenFlowSimulation<D>::velocityAt(const IVec<D>& cell) const {
  Vec<D> x;
  for (int a = 0; a < D; ++a) x[a] = (cell[a] + 0.5) * rd_.h();
  return u_.sample(x);
}

// Seed 004 fig. 24: the speed drives reaction rates, the direction the tensor.
template <int D>
void GivenFlowSimulation<D>::applyVelocityMaps() {
  const RDScene& R = scene_.rd;
  if (R.speedMaps.empty() && !R.anisotropy.directionFromVelocity) return;
  const size_t n = rd_.field(0).size();
  std::array<std::vector<double>, D> u;
  for (auto& c : u) c.resize(n);
  std::vector<double> speed(n);
  forEachCell<D>(rd_.cells(), [&](const IVec<D>& k, size_t i) {
    const Vec<D> v = velocityAt(k);
    double s2 = 0;
    for (int a = 0; a < D; ++a) u[size_t(a)][i] = v[a], s2 += v[a] * v[a];
    speed[i] = std::sqrt(s2);
  });
  if (!R.speedMaps.empty()) {
    if (!(referenceSpeed_ > 0)) {
      referenceSpeed_ = scene_.velocity.referenceSpeed > 0 ? scene_.velocity.referenceSpeed
                                                           : *std::max_element(speed.begin(), speed.end());
      if (!(referenceSpeed_ > 0)) referenceSpeed_ = 1.0;  // a still field: every cell at the range's low end
    }
    const double lo = scene_.velocity.speedRange[0], hi = scene_.velocity.speedRange[1];
    std::vector<double> p(n);
    for (size_t i = 0; i < n; ++i) p[i] = lo + (hi - lo) * std::min(speed[i] / referenceSpeed_, 1.0);
    for (int k : R.speedMaps) rd_.setParameterField(k, p);
  }
  if (R.anisotropy.directionFromVelocity) {
    DiffusionTensorSpec<D> spec = *rd_.diffusionTensorSpec();
    spec.direction = std::move(u);  // normalised by the tensor; zero speed: isotropic
    spec.lambda1 = lambda1_;
    spec.lambda2 = lambda2_;
    rd_.setDiffusionTensor(std::move(spec));
  }
}

// u_ always holds the velocity at time_: the step reads it (the coupled run's
// ARD step reads velocity n), and frames show it.
template <int D>
void GivenFlowSimulation<D>::step(double dt) {
  ard_->step(dt, u_);
  if (ard_->mode() != CouplingMode::Passive) stats_.add(rd_.lastStats());
  time_ += dt;
  ++steps_;
  sampleVelocity(time_);
}

template <int D>
std::vector<Grid<float, D>> GivenFlowSimulation<D>::ownField(const std::string& name) const {
  const bool speed = name == fields::kSpeed;
  if (!speed && name != fields::kVelocity) return speciesField<D>(rd_, name);
  std::vector<Grid<float, D>> v(speed ? 1 : size_t(D), Grid<float, D>(rd_.cells(), 0.0f));
  forEachCell<D>(rd_.cells(), [&](const IVec<D>& k, size_t i) {
    const Vec<D> c = velocityAt(k);
    double s2 = 0;
    for (int a = 0; a < D; ++a) s2 += c[a] * c[a];
    if (speed) v[0][i] = float(std::sqrt(s2));
    else
      for (int a = 0; a < D; ++a) v[size_t(a)][i] = float(c[a]);
  });
  return v;
}

template <int D>
void GivenFlowSimulation<D>::checkFinite(const std::string& when) const {
  morphoflow::checkFinite<D>(rd_, when, "the advection-reaction-diffusion step (" + rdStage(rd_.settings()) + ")");
}

template <int D>
void GivenFlowSimulation<D>::save(StateWriter* out) const {
  rd_.save(out);
  stats_.save(out);
  out->put("flow.time", time_);
  out->put("flow.steps", steps_);
  out->put("flow.reference_speed", referenceSpeed_);
}

template <int D>
void GivenFlowSimulation<D>::load(const StateReader& in) {
  rd_.load(in);
  stats_.load(in);
  in.get("flow.time", &time_);
  in.get("flow.steps", &steps_);
  in.get("flow.reference_speed", &referenceSpeed_);
  sampled_ = false;
  sampleVelocity(time_);
}

template <int D>
nlohmann::json GivenFlowSimulation<D>::resolved() const {
  const VelocityScene& v = scene_.velocity;
  nlohmann::json j = resolvedLayer<D>(scene_, rd_);
  if (!v.field.empty()) j["velocity"] = {{"field", v.field}};
  else j["velocity"] = {{"vdb", v.vdb}};
  return j;
}

template <int D>
void GivenFlowSimulation<D>::report(nlohmann::json* j) const {
  reportRDSolvers(stats_, rd_.steps(), j);
  if (!scene_.rd.speedMaps.empty()) (*j)["velocity_reference_speed"] = referenceSpeed_;
}

template class GivenFlowSimulation<2>;
template class GivenFlowSimulation<3>;

}  // namespace morphoflow
