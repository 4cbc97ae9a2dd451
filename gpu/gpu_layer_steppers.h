// The GPU's LayerSteppers (rd/layer_stepper.h): every integrator in the
// scene's precision (GpuRDLayer, gpu_rd_layer.h), and the plain explicit step of a
// two-species layer in single precision (GpuExplicitRD, gpu_explicit_rd.h).
// The species stay on the device; the host RDSolver gets a copy when asked.
#pragma once

#include <memory>

#include "gpu/gpu_counts.h"
#include "gpu/gpu_explicit_rd.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/layer_stepper.h"

namespace morphoflow {

template <int D>
class GpuLayerStepper final : public LayerStepper<D> {
 public:
  // The layer of `host` (whose operators it borrows: rd/layer_upload.h) from its current state.
  GpuLayerStepper(const RDSolver<D>& host, GpuPrecision real)
      : species_(host.model().info().species), layer_(layerUpload(host), real) {}

  void advance(double dt, long count) override;
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  // The layer's statistics as it reads them back (GpuRDLayer::lastStats).
  const RDRunStats* runStats() const override { return &stats_; }
  void toHost(RDSolver<D>* host) const override;
  void fromHost(const RDSolver<D>& host) override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  void resolved(nlohmann::json* j) const override;
  void report(nlohmann::json* run) const override;

 private:
  std::vector<std::string> species_;
  GpuRDLayer<D> layer_;
  RDRunStats stats_;
  double time_ = 0.0;
  long steps_ = 0;
  StepCounts counts_;
};

template <int D>
class GpuExplicitLayerStepper final : public LayerStepper<D> {
 public:
  // The model's uniform parameters, diffusion and current state of `host`.
  explicit GpuExplicitLayerStepper(const RDSolver<D>& host);

  void advance(double dt, long count) override;
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  const RDRunStats* runStats() const override { return nullptr; }
  void toHost(RDSolver<D>* host) const override;
  void fromHost(const RDSolver<D>& host) override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  void resolved(nlohmann::json* j) const override;
  void report(nlohmann::json* run) const override;

 private:
  std::vector<std::string> species_;
  std::unique_ptr<GpuExplicitRD> gpu_;
  double time_ = 0.0;
  long steps_ = 0;
  StepCounts counts_;
};

}  // namespace morphoflow
