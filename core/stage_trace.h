// StageTrace: named stages with the thread that ran them, written as Chrome
// trace-event JSON (chrome://tracing, ui.perfetto.dev) so the overlap of two
// schedules can be seen. Thread-safe; threads are numbered in order of first use.
#pragma once

#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace morphoflow {

// Seconds on the steady clock (the time base of StageTrace).
double traceClock();

class StageTrace {
 public:
  struct Event {
    std::string name, category;
    double begin, end;  // traceClock seconds
    int group, thread;  // group: 0 before the first beginGroup, then 1, 2, ...
  };

  // Events recorded after this call are grouped under `name` (a "process" in
  // the viewer: one benchmark case).
  void beginGroup(const std::string& name);
  // A stage that ran on the calling thread from `begin` to `end` (traceClock).
  void record(const std::string& name, const std::string& category, double begin, double end);
  std::vector<Event> events() const;
  // {"traceEvents": [...], "displayTimeUnit": "ms"}, times in microseconds
  // from the first event.
  std::string chromeJson() const;

 private:
  mutable std::mutex mutex_;
  std::vector<Event> events_;
  std::vector<std::string> groups_;
  std::unordered_map<std::thread::id, int> threads_;
};

}  // namespace morphoflow
