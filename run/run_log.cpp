#include "run/run_log.h"

#include <unistd.h>

#include <cmath>
#include <iostream>

#include <fmt/format.h>

namespace morphoflow {

namespace {

std::string clockTime(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = long(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60)
                   : fmt::format("{}:{:02d}", s / 60, s % 60);
}

}  // namespace

bool stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

RunLog::RunLog(bool quiet, bool terminal) : quiet_(quiet), terminal_(terminal) {}

void RunLog::say(const std::string& line) {
  endProgress();
  lines_.push_back(line);
  if (!quiet_) std::cerr << line << "\n" << std::flush;
}

void RunLog::warn(const std::string& line) {
  endProgress();
  lines_.push_back(line);
  std::cerr << line << "\n" << std::flush;
}

std::string RunLog::progressLine(long frame, long step, long totalSteps, double time, double endTime) const {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  const long done = step - startStep_;
  const double rate = elapsed > 0 ? double(done) / elapsed : 0.0;
  // ETA from simulated time where the run ends at a time, else from steps.
  double eta = NAN;
  if (endTime > 0 && time > startTime_) eta = elapsed * (endTime - time) / (time - startTime_);
  else if (totalSteps > 0 && done > 0) eta = elapsed * double(totalSteps - step) / double(done);
  std::string total = totalSteps > 0 ? fmt::format("/{}", totalSteps) : "";
  return fmt::format("frame {}  step {}{}  t = {:.5g}  {:.3g} steps/s  ETA {}", frame, step, total, time, rate,
                     clockTime(eta));
}

void RunLog::progress(long frame, long step, long totalSteps, double time, double endTime) {
  if (listener_) listener_(frame, step, totalSteps, time, endTime);
  const Clock::time_point now = Clock::now();
  if (startStep_ < 0) {
    startStep_ = step > 0 ? step - 1 : 0;
    startTime_ = time;
    start_ = now;
    return;
  }
  const bool lineDue = now - lastLine_ >= std::chrono::seconds(10);
  const bool drawDue = terminal_ && now - lastDraw_ >= std::chrono::milliseconds(100);
  if (!lineDue && !drawDue) return;
  const std::string line = progressLine(frame, step, totalSteps, time, endTime);
  if (lineDue) {
    lines_.push_back(line);
    lastLine_ = now;
  }
  if (quiet_) return;
  if (terminal_) {
    std::cerr << "\r" << line << "\x1b[K" << std::flush;
    drawn_ = true;
    lastDraw_ = now;
  } else if (lineDue) {
    std::cerr << line << "\n" << std::flush;
  }
}

void RunLog::endProgress() {
  if (drawn_ && !quiet_) std::cerr << "\n";
  drawn_ = false;
}

void RunLog::restore(const std::string& text) {
  std::vector<std::string> earlier;
  size_t at = 0;
  for (size_t nl; (nl = text.find('\n', at)) != std::string::npos; at = nl + 1)
    earlier.push_back(text.substr(at, nl - at));
  lines_.insert(lines_.begin(), earlier.begin(), earlier.end());
}

std::string RunLog::text() const {
  std::string s;
  for (const std::string& l : lines_) s += l + "\n";
  return s;
}

}  // namespace morphoflow
