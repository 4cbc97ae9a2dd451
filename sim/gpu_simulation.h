// --backend gpu: which scenes the GPU runs (every stage has a GPU program;
// any other scene is refused naming the first stage it lacks, and nothing
// falls back to the CPU), and the reaction-diffusion-only scenes as a
// Simulation: the explicit step in single precision (gpu/gpu_explicit_rd.h),
// every other integrator in double (gpu/gpu_rd_layer.h). Fluid and coupled
// scenes are FluidSimulation and CoupledSimulation on their gpu path.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/simulation.h"
#include "scenes/scene.h"

namespace morphoflow {

class GpuExplicitRD;
template <int D>
class GpuRDLayer;
template <int D>
class RDSolver;

// Throws UserError naming the stage when the scene needs one the GPU backend
// lacks, and when no OpenGL 4.3 context can be created (the reason).
void checkGpuRuns(const Scene& scene);

// The GL renderer and version ("llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core Profile) Mesa 22.3.6"),
// or the reason there is no context.
struct GpuInfo {
  bool available = false;
  std::string renderer, version, platform, reason;
};
GpuInfo gpuInfo();
// run.json: gl_renderer, gl_version, gl_platform of the context in use.
void recordGlContext(nlohmann::json* run);

template <int D>
class GpuRDSimulation : public Simulation<D> {
 public:
  GpuRDSimulation(const Scene& scene, const std::function<void(const std::string&)>& log);
  ~GpuRDSimulation() override;

  void step(double dt) override;
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  std::vector<std::string> fieldNames() const override { return species_; }
  std::vector<std::string> species() const override { return species_; }
  std::vector<std::string> dumpFieldNames() const override { return species_; }
  std::vector<Grid<float, D>> field(const std::string& name) const override;
  void checkFinite(const std::string& when) const override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  nlohmann::json resolved() const override;
  void report(nlohmann::json* run) const override;

 private:
  const Scene& scene_;
  std::vector<std::string> species_;
  IVec<D> cells_;
  double explicitLimit_ = 0.0;
  std::vector<float> download(int s) const;

  std::unique_ptr<GpuExplicitRD> gpu_;           // the explicit step, single precision
  std::unique_ptr<RDSolver<D>> host_;            // other integrators: the settings and operators
  std::unique_ptr<GpuRDLayer<D>> layer_;         // ... stepped in double precision
  nlohmann::json coarseReport_ = nlohmann::json::array();
  double time_ = 0.0;
  long steps_ = 0;
};

}  // namespace morphoflow
