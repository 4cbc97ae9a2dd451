#include "core/stage_trace.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace morphoflow {

namespace {

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      q += buf;
    } else {
      q += c;
    }
  }
  return q + "\"";
}

}  // namespace

double traceClock() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void StageTrace::beginGroup(const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  groups_.push_back(name);
}

void StageTrace::record(const std::string& name, const std::string& category, double begin, double end) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto [it, added] = threads_.try_emplace(std::this_thread::get_id(), int(threads_.size()));
  events_.push_back({name, category, begin, end, int(groups_.size()), it->second});
}

std::vector<StageTrace::Event> StageTrace::events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

std::string StageTrace::chromeJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  double t0 = events_.empty() ? 0.0 : events_.front().begin;
  for (const Event& e : events_) t0 = std::min(t0, e.begin);
  std::string out = "{\"displayTimeUnit\": \"ms\", \"traceEvents\": [\n";
  bool first = true;
  auto add = [&](const std::string& line) {
    out += (first ? "  " : ",\n  ") + line;
    first = false;
  };
  // Group 0 holds events recorded before any beginGroup; empty groups are left out.
  std::vector<bool> used(groups_.size() + 1, false);
  for (const Event& e : events_) used[size_t(e.group)] = true;
  for (size_t g = 0; g < used.size(); ++g)
    if (used[g])
      add("{\"name\": \"process_name\", \"ph\": \"M\", \"pid\": " + std::to_string(g) +
          ", \"args\": {\"name\": " + quoted(g == 0 ? std::string("morphoflow") : groups_[g - 1]) + "}}");
  for (const auto& [id, t] : threads_)
    for (size_t g = 0; g < used.size(); ++g)
      if (used[g])
        add("{\"name\": \"thread_name\", \"ph\": \"M\", \"pid\": " + std::to_string(g) + ", \"tid\": " +
          std::to_string(t) + ", \"args\": {\"name\": \"thread " + std::to_string(t) + "\"}}");
  char buf[96];
  for (const Event& e : events_) {
    std::snprintf(buf, sizeof buf, "\"ts\": %.3f, \"dur\": %.3f", 1e6 * (e.begin - t0), 1e6 * (e.end - e.begin));
    add("{\"name\": " + quoted(e.name) + ", \"cat\": " + quoted(e.category) + ", \"ph\": \"X\", " + buf +
        ", \"pid\": " + std::to_string(e.group) + ", \"tid\": " + std::to_string(e.thread) + "}");
  }
  return out + "\n]}\n";
}

}  // namespace morphoflow
