// A scene's timeline: numeric keys that change during a run (keyframes),
// field edits at a time ([[deposits]]), and strokes and obstacles that appear
// (and obstacles that go) at a time. The studio records its edits in this
// form, and `morphoflow run` replays them (sim/timeline_simulation.h).
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"

namespace morphoflow {

// key = { keys = [[t, value], ...], interpolation = "step" | "linear" }.
struct KeyedValue {
  std::string key;                         // "rd.parameters.F"
  bool linear = false;                     // false: each value holds until the next key
  bool array = false;                      // the value is an array of numbers (rd.diffusion)
  std::vector<double> times;               // ascending, >= 0
  std::vector<std::vector<double>> values; // one per time (one number unless `array`)
  SourceLocation where;
  std::vector<SourceLocation> places;      // of each key's value

  // The value at time t: the first value before the first key, the last after the last.
  std::vector<double> at(double t) const;
  // As TOML text ("0.04", "[2e-05, 1e-05]"), each number the shortest that reads back the same.
  std::string textAt(double t) const;
};

// [[deposits]]: at time t, the cells of `field` within `radius` of `center`
// (domain units) are set to `value` (a brush dab: chemical, dye or heat).
struct Deposit {
  double time = 0.0;
  std::string field;
  std::array<double, 3> center{0.0, 0.0, 0.0};
  double radius = 0.0;
  double value = 0.0;
  SourceLocation where;
};

// When an element of the scene exists: [start, end).
struct TimeWindow {
  double start = 0.0;
  double end = std::numeric_limits<double>::infinity();
  bool contains(double t) const { return start <= t && t < end; }
};

struct SceneTimeline {
  std::vector<KeyedValue> keyed;
  std::vector<Deposit> deposits;             // in order of time (stable)
  std::vector<TimeWindow> obstacles;         // per [[obstacles]] entry
  std::vector<double> strokeStarts;          // per [[rd.strokes]] entry
  // The scene's text and --set overrides, to read it again at a time.
  std::string text;
  std::vector<std::string> overrides;

  // Whether anything changes during the run.
  bool empty() const;
  // The --set overrides that give the keyed values at time t.
  std::vector<std::string> overridesAt(double t) const;
};

// The keys whose change means something mid-run (the studio's controls, and
// the keys that may take keyframes): a '*' stands for one part of the path.
const std::vector<std::string>& steerableKeyPatterns();
bool isSteerableKey(const std::string& key);

// Whether an event at `eventTime` is due at a step that starts at `t` with
// step dt (a millionth of the step's slack, the same wherever it is asked).
inline bool dueAt(double eventTime, double t, double dt) { return eventTime <= t + 1e-6 * dt; }

}  // namespace morphoflow
