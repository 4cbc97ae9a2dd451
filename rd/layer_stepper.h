// LayerStepper<D>: what advances a reaction-diffusion layer, with one shape
// for every backend. The host RDSolver (rd_solver.h) holds the state that
// fields and checks read: CpuLayerStepper steps it in place,
// FusedLayerStepper steps float species in one fused pass
// (fused_explicit.h), the GPU's (gpu/gpu_layer_steppers.h) keep the species
// on the device; those copy the state into the host when asked.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "core/state_archive.h"
#include "rd/fused_explicit.h"
#include "rd/rd_solver.h"

namespace morphoflow {

// Statistics of an RD layer's steps, for run.json.
struct RDRunStats {
  NewtonStats newton;
  long diffusionIterations = 0;
  int diffusionMax = 0, unconverged = 0;
  void add(const RDStepStats& st);
  void save(StateWriter* out) const;
  void load(const StateReader& in);
};

template <int D>
class LayerStepper {
 public:
  virtual ~LayerStepper() = default;

  // `count` steps of dt.
  virtual void advance(double dt, long count) = 0;
  // The steps one pass takes together (advance's count gains from a multiple).
  virtual long stepsTogether() const { return 1; }
  virtual double time() const = 0;
  virtual long steps() const = 0;
  // The Newton and diffusion statistics over the run (null: a step with neither).
  virtual const RDRunStats* runStats() const = 0;
  // The species into `host` (nothing where the host is what is stepped),
  // and from it (after its fields were set).
  virtual void toHost(RDSolver<D>* host) const = 0;
  virtual void fromHost(const RDSolver<D>& host) = 0;
  // Checkpoints: the layer's whole state.
  virtual void save(StateWriter* out) const = 0;
  virtual void load(const StateReader& in) = 0;
  // run.json: how the layer is stepped ("resolved"), the backend's own entries.
  virtual void resolved(nlohmann::json* resolved) const = 0;
  virtual void report(nlohmann::json*) const {}
};

// The host RDSolver's own step (every integrator, map, tensor, lobe and held cell).
template <int D>
class CpuLayerStepper final : public LayerStepper<D> {
 public:
  explicit CpuLayerStepper(RDSolver<D>* rd) : rd_(rd) {}

  void advance(double dt, long count) override;
  double time() const override { return rd_->time(); }
  long steps() const override { return rd_->steps(); }
  const RDRunStats* runStats() const override { return &stats_; }
  void toHost(RDSolver<D>*) const override {}
  void fromHost(const RDSolver<D>&) override {}
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  void resolved(nlohmann::json* j) const override;

 private:
  RDSolver<D>* rd_;
  RDRunStats stats_;
};

// The explicit step of a plain layer (uniform parameters, no tensor, lobes or
// held cells) on float species, one fused pass; the host holds the start and
// the copy outputs read. Checkpoints keep the host's format, and the clock.
template <int D>
class FusedLayerStepper final : public LayerStepper<D> {
 public:
  // Null where the model has no fused engine.
  static std::unique_ptr<FusedLayerStepper> create(RDSolver<D>* host, const std::vector<int>& generalizedSpecies);

  void advance(double dt, long count) override;
  long stepsTogether() const override { return fused_->stepsPerPass(); }
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  // (no Newton and no solves: statistics of nothing, as run.json has them)
  const RDRunStats* runStats() const override;
  void toHost(RDSolver<D>* host) const override;
  void fromHost(const RDSolver<D>&) override { fromHost(); }
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  void resolved(nlohmann::json* j) const override;

 private:
  FusedLayerStepper(RDSolver<D>* host, std::unique_ptr<FusedExplicitRD<D>> fused);
  void fromHost();

  RDSolver<D>* host_;
  std::unique_ptr<FusedExplicitRD<D>> fused_;
  double time_ = 0.0;
  long steps_ = 0;
};

}  // namespace morphoflow
