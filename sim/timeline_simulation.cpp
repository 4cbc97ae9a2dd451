#include "sim/timeline_simulation.h"

#include <cmath>
#include <limits>

#include "scenes/scene_loader.h"

namespace morphoflow {

template <int D>
TimelineSimulation<D>::TimelineSimulation(const Scene& scene, Factory make)
    : scene_(std::make_shared<const Scene>(scene)), make_(std::move(make)) {
  rebuildAt(0.0);
  rebuilds_ = 0;
}

// The keyed values at t, then 1 or 0 for each obstacle and stroke that exists then.
template <int D>
std::vector<double> TimelineSimulation<D>::signatureAt(double t) const {
  const SceneTimeline& tl = scene_->timeline;
  std::vector<double> s;
  for (const KeyedValue& k : tl.keyed)
    for (double v : k.at(t)) s.push_back(v);
  for (const TimeWindow& w : tl.obstacles) s.push_back(w.contains(t) ? 1.0 : 0.0);
  for (double start : tl.strokeStarts) s.push_back(start <= t ? 1.0 : 0.0);
  return s;
}

template <int D>
void TimelineSimulation<D>::rebuildAt(double t) {
  auto scene = std::make_unique<Scene>(sceneAt(*scene_, t));
  std::unique_ptr<Simulation<D>> next = make_(*scene);
  if (inner_) {
    std::string bytes;
    StateWriter w([&bytes](std::string_view frame, const void* data, size_t n) {
      bytes.append(frame);
      bytes.append(static_cast<const char*>(data), n);
    });
    inner_->save(&w);
    next->load(StateReader(std::move(bytes)));
    ++rebuilds_;
  }
  inner_ = std::move(next);  // (before built_: the old simulation refers to the old scene)
  built_ = std::move(scene);
  builtAt_ = t;
  stale_ = false;
  signature_ = signatureAt(t);
}

// A brush dab: the cells of the field within the radius set to the value
// (NaN elsewhere: setField leaves those cells as they are).
template <int D>
void TimelineSimulation<D>::deposit(const Deposit& d) {
  const std::vector<Grid<float, D>> now = inner_->field(d.field);
  Grid<float, D> dab(now[0].dims(), std::numeric_limits<float>::quiet_NaN());
  const double h = built_->fluid.size[0] / double(dab.dims()[0]);
  for (size_t i = 0; i < dab.size(); ++i) {
    const IVec<D> c = dab.coord(i);
    double r2 = 0.0;
    for (int a = 0; a < D; ++a) {
      const double x = (c[a] + 0.5) * h - d.center[size_t(a)];
      r2 += x * x;
    }
    if (r2 <= d.radius * d.radius) dab[i] = float(d.value);
  }
  inner_->setField(d.field, dab);
}

template <int D>
void TimelineSimulation<D>::prepare(double dt) {
  const double t = inner_->time(), te = t + 1e-6 * dt;  // (scenes/timeline.h, dueAt)
  if (stale_ || signatureAt(te) != signature_) rebuildAt(te);
  const std::vector<Deposit>& deposits = scene_->timeline.deposits;
  for (; deposited_ < deposits.size() && dueAt(deposits[deposited_].time, t, dt); ++deposited_)
    deposit(deposits[deposited_]);
}

template <int D>
void TimelineSimulation<D>::step(double dt) {
  prepare(dt);
  inner_->step(dt);
}

template <int D>
void TimelineSimulation<D>::advance(double dt, long count) {
  for (long k = 0; k < count; ++k) step(dt);
}

// One at a time: the scene may change between any two steps.
template <int D>
long TimelineSimulation<D>::stepsTogether() const {
  return 1;
}

template <int D>
void TimelineSimulation<D>::save(StateWriter* out) const {
  inner_->save(out);
  out->put("timeline.built_at", builtAt_);
  out->put("timeline.deposited", uint64_t(deposited_));
}

template <int D>
void TimelineSimulation<D>::load(const StateReader& in) {
  double at = 0.0;
  uint64_t deposited = 0;
  in.get("timeline.built_at", &at);
  in.get("timeline.deposited", &deposited);
  if (deposited > scene_->timeline.deposits.size())
    throw StateError("section 'timeline.deposited' counts more deposits than the scene has");
  inner_.reset();
  rebuildAt(at);
  inner_->load(in);
  deposited_ = size_t(deposited);
}

template <int D>
void TimelineSimulation<D>::report(nlohmann::json* run) const {
  inner_->report(run);
  (*run)["timeline"] = {{"rebuilds", rebuilds_}, {"deposits_applied", deposited_}};
}

template <int D>
void TimelineSimulation<D>::retarget(const Scene& scene) {
  scene_ = std::make_shared<const Scene>(scene);
  // Built for the coming step already (`prepare`): the edit, made at the
  // current time, is not in what was built, so the next `prepare` builds again.
  stale_ = builtAt_ >= inner_->time();
  signature_ = signatureAt(builtAt_);
}

template class TimelineSimulation<2>;
template class TimelineSimulation<3>;

}  // namespace morphoflow
