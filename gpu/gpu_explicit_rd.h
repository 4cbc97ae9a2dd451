// The explicit Euler step of a two-species reaction-diffusion layer on the
// GPU (shaders/rd_explicit.comp): the species live in storage buffers, two
// per species (read one, write the other), and leave the GPU only when asked.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "rd/rd_settings.h"

namespace morphoflow {

class ComputeProgram;

// The GLSL body of REACTION(u, v, r) for a two-species model (its
// parameters in the uniform p[8], in order), or "" when it has no GPU program yet.
std::string gpuReaction(const std::string& model);

class GpuExplicitRD {
 public:
  // `params` are the model's uniform parameters; `u`, `v` the initial species.
  GpuExplicitRD(const RDSettings& settings, const std::vector<double>& diffusion, const std::vector<double>& params,
                const std::vector<float>& u, const std::vector<float>& v);
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
  std::unique_ptr<ComputeProgram> program_;
  std::array<unsigned, 4> buffers_{};  // u, v, u', v'
  int current_ = 0;                     // 0: (u, v) hold the state, 1: (u', v')
};

}  // namespace morphoflow
