// What a run says: messages and progress lines go to stderr (unless --quiet)
// and are kept for DIR/log.txt. The progress line is redrawn in place on a
// terminal; elsewhere (a pipe, a file, a farm's log) it is a plain line at
// most every 10 s, with no carriage returns.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace morphoflow {

class RunLog {
 public:
  RunLog(bool quiet, bool terminal);
  // A message: one line on stderr and in the log.
  void say(const std::string& line);
  // A warning: as say(), but shown even with --quiet.
  void warn(const std::string& line);
  // A line for the log only (the caller reports it otherwise).
  void keep(const std::string& line) { lines_.push_back(line); }
  // Progress after a step: frame, step (of about `totalSteps`, 0 if not
  // known), simulated time (of `endTime`, 0 if not known).
  void progress(long frame, long step, long totalSteps, double time, double endTime);
  // Also hands each progress report to `listener` (the Python module's callback).
  using Listener = std::function<void(long frame, long step, long totalSteps, double time, double endTime)>;
  void listen(Listener listener) { listener_ = std::move(listener); }
  // Ends a progress line drawn in place.
  void endProgress();
  // The lines so far, as DIR/log.txt holds them.
  std::string text() const;
  // Puts back the lines of an interrupted run (text()'s output) before this one's.
  void restore(const std::string& text);

 private:
  using Clock = std::chrono::steady_clock;
  std::string progressLine(long frame, long step, long totalSteps, double time, double endTime) const;
  Listener listener_;
  bool quiet_, terminal_;
  bool drawn_ = false;
  std::vector<std::string> lines_;
  Clock::time_point start_ = Clock::now(), lastDraw_{}, lastLine_ = Clock::now();
  long startStep_ = -1;
  double startTime_ = 0.0;
};

// Whether stderr is a terminal.
bool stderrIsTerminal();

}  // namespace morphoflow
