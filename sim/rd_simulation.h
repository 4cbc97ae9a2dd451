// RDSimulation<D>: a reaction-diffusion-only scene (no [fluid]) as a
// Simulation: the scene's initial state (grown coarse to fine where the scene
// asks), its maps and anisotropy, and the solvers' statistics.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/simulation.h"
#include "rd/fused_explicit.h"
#include "rd/rd_solver.h"
#include "scenes/scene.h"

namespace morphoflow {

// Whether the scene's layer takes the fused explicit step (rd/fused_explicit.h).
bool fusedExplicitFits(const Scene& scene);

// Statistics of an RD layer's steps, for run.json.
struct RDRunStats {
  NewtonStats newton;
  long diffusionIterations = 0;
  int diffusionMax = 0, unconverged = 0;
  void add(const RDStepStats& st);
  void save(StateWriter* out) const;
  void load(const StateReader& in);
};

// run.json's "solvers": the Newton and diffusion statistics of `rdSteps` steps.
void reportRDSolvers(const RDRunStats& stats, long rdSteps, nlohmann::json* run);

// run.json's "resolved" values of a scene's RD layer (with the generalized
// diffusion's spectral radius where it has one).
template <int D>
nlohmann::json resolvedLayer(const Scene& scene, const RDSolver<D>& rd);

// The species of an RD layer as fields.
template <int D>
std::vector<Grid<float, D>> speciesField(const RDSolver<D>& rd, const std::string& name);

template <int D>
class RDSimulation : public Simulation<D> {
 public:
  using Log = std::function<void(const std::string&)>;
  RDSimulation(const Scene& scene, const Log& log);

  void step(double dt) override { advance(dt, 1); }
  void advance(double dt, long count) override;
  long stepsTogether() const override { return fused_ ? fused_->stepsPerPass() : 1; }
  double time() const override { return fused_ ? time_ : rd_.time(); }
  long steps() const override { return fused_ ? steps_ : rd_.steps(); }
  std::vector<std::string> fieldNames() const override { return species(); }
  std::vector<std::string> species() const override { return rd_.model().info().species; }
  std::vector<std::string> dumpFieldNames() const override { return species(); }
  std::vector<Grid<float, D>> field(const std::string& name) const override;
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 private:
  void toFused();
  void syncHost() const;

  const Scene& scene_;
  mutable RDSolver<D> rd_;
  // The explicit step of a plain layer (uniform parameters, no tensor, lobes
  // or held cells): float species, one fused pass (rd/fused_explicit.h); the
  // RDSolver then only builds the start and holds a copy for outputs.
  std::unique_ptr<FusedExplicitRD<D>> fused_;
  double time_ = 0.0;
  long steps_ = 0;
  mutable bool hostStale_ = false;
  nlohmann::json coarseReport_ = nlohmann::json::array();
  RDRunStats stats_;
};

}  // namespace morphoflow
