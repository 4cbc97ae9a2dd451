// time.until_steady: at each frame, the velocity's relative change per unit
// time since the frame before,
//   r = ||u(t1) - u(t0)||_2 / (||u(t1)||_2 (t1 - t0)),
// over every cell-centred component; the run is steady once r < tolerance.
// The reference (the last frame's velocity and time) goes into checkpoints,
// so a resumed run stops at the step an uninterrupted one does.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "core/grid.h"
#include "sim/simulation.h"
#include "core/state_archive.h"

namespace morphoflow {

template <int D>
class SteadyState {
 public:
  explicit SteadyState(double tolerance) : tolerance_(tolerance) {}

  // Takes the simulation's velocity now as the reference.
  void reference(const Simulation<D>& sim) {
    reference_ = sim.field(fields::kVelocity);
    time_ = sim.time();
  }

  // The change since the reference; the velocity now becomes the reference.
  // Returns whether the run is steady.
  bool check(const Simulation<D>& sim) {
    std::vector<Grid<float, D>> u = sim.field(fields::kVelocity);
    double diff2 = 0.0, norm2 = 0.0;
    for (size_t c = 0; c < u.size(); ++c)
      for (size_t i = 0; i < u[c].size(); ++i) {
        const double d = double(u[c][i]) - double(reference_[c][i]);
        diff2 += d * d;
        norm2 += double(u[c][i]) * double(u[c][i]);
      }
    const double span = sim.time() - time_;
    change_ = diff2 == 0.0 ? 0.0 : std::sqrt(diff2) / (std::sqrt(norm2) * span);
    if (!std::isfinite(change_)) change_ = std::numeric_limits<double>::infinity();
    reference_ = std::move(u);
    time_ = sim.time();
    checked_ = true;
    return steady();
  }

  bool steady() const { return checked_ && change_ < tolerance_; }
  bool checked() const { return checked_; }
  double change() const { return change_; }
  double tolerance() const { return tolerance_; }

  void save(StateWriter* out) const {
    out->put("steady.time", time_);
    out->put("steady.components", uint64_t(reference_.size()));
    for (size_t c = 0; c < reference_.size(); ++c) out->putGrid("steady.velocity." + std::to_string(c), reference_[c]);
  }
  // After the simulation's own state: its velocity's shape says what to read.
  void load(const StateReader& in, const Simulation<D>& sim) {
    reference_ = sim.field(fields::kVelocity);
    uint64_t n = 0;
    in.get("steady.components", &n);
    if (n != reference_.size()) throw StateError("section 'steady.components' does not match the velocity");
    in.get("steady.time", &time_);
    for (size_t c = 0; c < reference_.size(); ++c) in.getGrid("steady.velocity." + std::to_string(c), &reference_[c]);
  }

 private:
  double tolerance_;
  std::vector<Grid<float, D>> reference_;
  double time_ = 0.0;
  double change_ = std::numeric_limits<double>::infinity();
  bool checked_ = false;
};

}  // namespace morphoflow
