#include "scenes/timeline.h"

#include <algorithm>

#include <fmt/format.h>

namespace morphoflow {

std::vector<double> KeyedValue::at(double t) const {
  // The last key at or before t (a step's value holds until the next key).
  const size_t next = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  if (next == 0) return values.front();
  if (next == times.size() || !linear) return values[next - 1];
  const double t0 = times[next - 1], t1 = times[next], w = (t - t0) / (t1 - t0);
  std::vector<double> v(values[next - 1].size());
  for (size_t k = 0; k < v.size(); ++k) v[k] = values[next - 1][k] + w * (values[next][k] - values[next - 1][k]);
  return v;
}

std::string KeyedValue::textAt(double t) const {
  const std::vector<double> v = at(t);
  if (!array) return fmt::format("{}", v[0]);
  return fmt::format("[{}]", fmt::join(v, ", "));
}

bool SceneTimeline::empty() const {
  if (!keyed.empty() || !deposits.empty()) return false;
  for (const TimeWindow& w : obstacles)
    if (w.start > 0.0 || w.end != std::numeric_limits<double>::infinity()) return false;
  for (double s : strokeStarts)
    if (s > 0.0) return false;
  return true;
}

std::vector<std::string> SceneTimeline::overridesAt(double t) const {
  std::vector<std::string> out = overrides;
  for (const KeyedValue& k : keyed) out.push_back(k.key + "=" + k.textAt(t));
  return out;
}

const std::vector<std::string>& steerableKeyPatterns() {
  static const std::vector<std::string> keys = {
      "rd.parameters.*",   "rd.diffusion",          "fluid.viscosity",       "fluid.reynolds",
      "fluid.lid_velocity", "fluid.buoyancy",       "fluid.force",           "inflow.mean_velocity",
      "smoke.buoyancy",    "smoke.vorticity",       "smoke.cooling",         "smoke.dissipation",
      "smoke.weight",      "smoke.ambient",         "sources.*.density",     "sources.*.temperature",
      "sources.*.velocity", "coupling.rd_time_scale", "coupling.smoke_mask"};
  return keys;
}

bool isSteerableKey(const std::string& key) {
  auto parts = [](const std::string& s) {
    std::vector<std::string> p;
    size_t a = 0;
    for (size_t b; (b = s.find('.', a)) != std::string::npos; a = b + 1) p.push_back(s.substr(a, b - a));
    p.push_back(s.substr(a));
    return p;
  };
  const std::vector<std::string> k = parts(key);
  for (const std::string& pattern : steerableKeyPatterns()) {
    const std::vector<std::string> p = parts(pattern);
    if (p.size() != k.size()) continue;
    bool match = true;
    for (size_t i = 0; i < p.size() && match; ++i) match = p[i] == "*" || p[i] == k[i];
    if (match) return true;
  }
  return false;
}

}  // namespace morphoflow
