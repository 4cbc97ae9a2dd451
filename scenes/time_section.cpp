// [time]: the step, and how many (steps) or how long (duration); the CFL
// limit; until_steady.
#include <fmt/format.h>

#include "scenes/scene_reader.h"

namespace morphoflow {

constexpr long kMaxSteps = TimeSettings::kMaxSteps;

void parseTime(SceneContext& c, Scene* sp) {
  Reader& r = c.r;
  toml::table& root = c.root;
  Scene& s = *sp;
  const toml::table* time = r.table(root, "", "time");
  s.time.dt = r.number(time, "time.", "dt", 0.01, 0, 1e6, true);
  const toml::node* stepsNode = r.node(time, "time.", "steps");
  const toml::node* durNode = r.node(time, "time.", "duration");
  if (stepsNode && durNode) r.fail(durNode, "time.duration", "give either time.steps or time.duration, not both");
  s.time.steps = r.integer(time, "time.", "steps", 0, 1, kMaxSteps);
  s.time.duration = r.number(time, "time.", "duration", 0.0, 0, 1e9, true);
  s.time.untilSteady = r.number(time, "time.", "until_steady", 0.0, 0, 1e6);  // 0: off
  if (!stepsNode && !durNode) {
    if (s.time.untilSteady > 0)
      s.time.duration = TimeSettings::kSteadyCap;
    else
      s.time.steps = 100;
  }
  s.time.cfl = r.number(time, "time.", "cfl", 0.0, 0, 1000);
  if (durNode && s.time.duration <= TimeSettings::kEndTolerance)
    r.fail(durNode, "time.duration", fmt::format("duration {:g} is too short for a single step", s.time.duration),
           "give a duration of at least one step, or time.steps");
  // The work a scene asks for is bounded before any of it is done.
  if (durNode && !(s.time.duration / s.time.dt <= double(kMaxSteps)))
    r.fail(durNode, "time.duration",
           fmt::format("duration {:g} at dt = {:g} is {:.3g} steps, more than {}", s.time.duration, s.time.dt,
                       s.time.duration / s.time.dt, kMaxSteps),
           "use a larger time.dt or a shorter time.duration");
}

void checkUntilSteady(SceneContext& c, const Scene& s) {
  if (s.time.untilSteady <= 0 || s.hasFluid) return;
  const toml::table* time = c.r.table(c.root, "", "time");
  c.r.fail(c.r.node(time, "time.", "until_steady"), "time.until_steady",
           "time.until_steady ends a run when its fluid's velocity is steady, and this scene has no fluid",
           "remove time.until_steady and give time.steps or time.duration");
}

}  // namespace morphoflow
