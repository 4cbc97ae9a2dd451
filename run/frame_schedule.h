// Which steps write a frame: every output.every steps (frame 0 is the
// initial state), within --frames A:B; the run stops at frame B.
#pragma once

#include "run/run_options.h"
#include "scenes/scene.h"

namespace morphoflow {

class FrameSchedule {
 public:
  FrameSchedule(int every, const RunOptions& options)
      : every_(every), first_(options.firstFrame), last_(options.lastFrame) {}
  // The frame number step writes, or -1 if it writes none.
  long frameAt(long step) const {
    if (step % every_ != 0) return -1;
    const long frame = step / every_;
    if (frame < first_ || (last_ >= 0 && frame > last_)) return -1;
    return frame;
  }
  // Whether the run is done at step `step`: --frames' B is written. (It
  // stops there, so its final checkpoint is at B's step and a resume writes B + 1.)
  bool pastLast(long step) const { return last_ >= 0 && step >= long(last_) * every_; }
  int every() const { return every_; }

 private:
  int every_;
  long first_, last_;
};

}  // namespace morphoflow
