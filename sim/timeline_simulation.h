// A simulation whose scene changes as it runs (scenes/timeline.h): before
// each step, the keyed values, strokes and obstacles of the scene at that
// time are compared with those the running simulation was built from; when
// they differ, the simulation is built again from the scene at that time and
// takes over the state (save, then load: bit for bit what it would have
// continued from). Then the deposits that are due set their cells. `run`
// replays a timeline this way, and the studio extends one as it is edited.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/simulation.h"
#include "scenes/scene.h"

namespace morphoflow {

template <int D>
class TimelineSimulation : public Simulation<D> {
 public:
  using Factory = std::function<std::unique_ptr<Simulation<D>>(const Scene&)>;
  // `scene` must have the same structure at every time (resolution, model,
  // kind of simulation): only its timeline's keys and elements change.
  TimelineSimulation(const Scene& scene, Factory make);

  void step(double dt) override;
  void advance(double dt, long count) override;
  long stepsTogether() const override;
  double cflTimeStep(double cfl, double dtMax) const override { return inner_->cflTimeStep(cfl, dtMax); }
  double time() const override { return inner_->time(); }
  long steps() const override { return inner_->steps(); }
  const Scene& scene() const override { return *scene_; }
  std::vector<std::string> species() const override { return inner_->species(); }
  void setField(const std::string& name, const Grid<float, D>& values) override { inner_->setField(name, values); }
  bool hasObstacles() const override { return inner_->hasObstacles(); }
  std::vector<std::pair<std::string, std::string>> measurementFiles() const override {
    return inner_->measurementFiles();
  }
  void checkFinite(const std::string& when) const override { inner_->checkFinite(when); }
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override { return inner_->resolved(); }
  void report(nlohmann::json* run) const override;

  // The studio: the same scene with a timeline that only adds to this one
  // at the current time or later. Takes effect at the next step.
  void retarget(const Scene& scene);
  // What the scene changes before the step of `dt` from the current time
  // (a rebuild, the deposits due), done now; `step` does it first. Lets the
  // studio show an edit made while paused without taking a step.
  void prepare(double dt);
  // The scene the running simulation was built from (the timeline's at the last change).
  const Scene& current() const { return *built_; }
  // How many times the simulation was built again.
  long rebuilds() const { return rebuilds_; }

 protected:
  std::vector<Grid<float, D>> ownField(const std::string& name) const override { return inner_->field(name); }

 private:
  std::vector<double> signatureAt(double t) const;
  void rebuildAt(double t);
  void deposit(const Deposit& d);

  std::shared_ptr<const Scene> scene_;  // with its timeline
  Factory make_;
  std::unique_ptr<Scene> built_;        // the scene at builtAt_ (the inner simulation holds a reference)
  std::unique_ptr<Simulation<D>> inner_;
  double builtAt_ = 0.0;
  std::vector<double> signature_;
  bool stale_ = false;  // what was built lacks an edit made since (retarget)
  size_t deposited_ = 0;                // deposits applied
  long rebuilds_ = 0;
};

}  // namespace morphoflow
