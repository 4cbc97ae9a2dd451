// The explicit Euler step of a two-species reaction-diffusion layer on the
// GPU (shaders/rd_explicit.comp): the species live in storage buffers, two
// per species (read one, write the other), and leave the GPU only when asked.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "gpu/gpu_models.h"
#include "rd/rd_settings.h"

namespace morphoflow {

class ComputeProgram;

class GpuExplicitRD {
 public:
  // `params` are the model's uniform parameters; `clamped` the species held
  // >= 0 after each step (the model's projection); `u`, `v` the initial species.
  GpuExplicitRD(const RDSettings& settings, const std::vector<double>& diffusion, const std::vector<double>& params,
                const std::vector<int>& clamped, const std::vector<float>& u, const std::vector<float>& v);
  ~GpuExplicitRD();
  GpuExplicitRD(const GpuExplicitRD&) = delete;
  GpuExplicitRD& operator=(const GpuExplicitRD&) = delete;

  void step(double dt);                        // queued; returns before the GPU is done
  void finish() const;                         // waits for every queued step (benchmarks)
  std::vector<float> download(int species) const;  // waits for the queued steps
  void upload(int species, const std::vector<float>& values);
  size_t cells() const { return n_; }

 private:
  std::array<int, 3> cells_{1, 1, 1};
  size_t n_ = 1;
  double h_ = 1.0;
  std::array<float, 2> dOverH2_{};
  std::array<float, 8> params_{};
  bool periodic_ = true;
  unsigned clamped_ = 0;
  std::unique_ptr<ComputeProgram> program_;
  std::array<unsigned, 4> buffers_{};  // u, v, u', v'
  int current_ = 0;                     // 0: (u, v) hold the state, 1: (u', v')
};

}  // namespace morphoflow
