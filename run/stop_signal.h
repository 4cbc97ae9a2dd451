// SIGINT and SIGTERM ask a run to stop: the driver finishes the current step,
// writes a checkpoint, says where, and exits 128 + the signal (130, 143).
// The handler only records the signal (the one global a signal needs).
#pragma once

namespace morphoflow {

class StopSignals {
 public:
  StopSignals();   // installs the handlers
  ~StopSignals();  // restores the previous ones
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  // 0 until a signal arrives, then SIGINT or SIGTERM.
  static int received();
};

}  // namespace morphoflow
