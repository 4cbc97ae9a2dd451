// HostCopy: the host's copy of a state that is stepped elsewhere (on the
// GPU, or in a float engine), refreshed by the one function given, and only
// when the host reads it after a step moved the state on.
#pragma once

#include <functional>
#include <utility>

namespace morphoflow {

class HostCopy {
 public:
  explicit HostCopy(std::function<void()> refresh) : refresh_(std::move(refresh)) {}

  // The state moved on (a step, a checkpoint loaded into the stepper).
  void stepped() { stale_ = true; }
  // Before the host reads: the state copied into it if it is older.
  void refresh() const {
    if (!stale_) return;
    refresh_();
    stale_ = false;
  }

 private:
  std::function<void()> refresh_;
  mutable bool stale_ = false;
};

}  // namespace morphoflow
