// The GPU's own time of a step's stages: timestamp queries (GL timer
// queries) at the stage boundaries, read a step later, so that timing never
// makes the host wait for the GPU or drains its queue.
#pragma once

#include <array>
#include <vector>

#include "gpu/gpu_counts.h"

namespace morphoflow {

class GpuStageTimer {
 public:
  explicit GpuStageTimer(int stages);
  ~GpuStageTimer();
  GpuStageTimer(const GpuStageTimer&) = delete;
  GpuStageTimer& operator=(const GpuStageTimer&) = delete;

  // A timestamp at boundary k of this step (0: its start, k: the end of stage k - 1).
  void mark(int boundary);
  // Ends the step: the seconds of each stage of the step before it (zeros
  // for the first step), which the GPU has finished by now.
  std::vector<double> endStep();
  // The steps ended.
  long steps() const { return steps_; }
  // run.json's per-stage counts: {name: perStep(...)} for the stages named.
  nlohmann::json countsPerStep(const char* const* names) const;

 private:
  int stages_;
  std::array<std::vector<unsigned>, 2> queries_;  // two steps' worth, alternating
  int current_ = 0;
  bool previous_ = false;  // the other set holds a finished step
  std::vector<GpuCounts> counts_;
  GpuCounts atMark_;
  long steps_ = 0;
};

}  // namespace morphoflow
