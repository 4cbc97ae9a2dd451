// Progress and cancellation, passed into long-running work; solvers never print.
#pragma once

#include <atomic>

namespace morphoflow {

class Interrupter {
 public:
  virtual ~Interrupter() = default;
  // Return true to cancel. `fraction` is in [0, 1] when known, else < 0.
  virtual bool progress(double fraction) { return cancelled_.load(); }
  void cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }

 private:
  std::atomic<bool> cancelled_{false};
};

}  // namespace morphoflow
