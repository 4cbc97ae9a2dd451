// A Krylov solve's convergence decided on the device. While a gate is
// entered, every dispatch is indirect (glDispatchComputeIndirect): its
// groups come from the gate's argument buffer, which the stopping test
// (shaders/gate_logic.glsl: the gate's kernel at a solve's start and end, the
// p update's last pass after each iteration) sets to the dispatch's own
// groups while the solve has not converged and to zero once it has, reading
// the solve's scalars in place. So the host queues a bounded number of iterations without reading
// anything back, and the iterations past convergence do no work: the result
// is the iterate at the CPU's stopping test, at the CPU's iteration count.
// The gate also tallies each solve (iterations, whether it converged, the
// true residual) on the device, for the host to read when it wants them.
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "gpu/gpu_buffer.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

// When a stepper reads its solves' tallies: steps 1, 2, 4 and 8 (while the
// schedules settle), then every kStatsEvery-th (step counts from 1).
constexpr long kStatsEvery = 16;
inline bool statsDue(long step) { return step == 1 || step == 2 || step == 4 || step == 8 || step % kStatsEvery == 0; }

// Sums whose final pass a gate's kernel makes first (fused_sum.glsl): up to
// two slots of `partials`, each of `groups` partials.
struct GateFinals {
  const GpuBuffer* partials = nullptr;
  int slots[2] = {-1, -1};
  unsigned groups = 0;
};

class GpuGate final : public DispatchRoute {
 public:
  // The scalar slots of the solve's reduction buffer the kernel reads.
  struct Slots {
    int bb, rr, pq;
  };
  using Finals = GateFinals;
  // What the device counted since the last reset.
  struct Tally {
    uint32_t solves = 0, iterations = 0, maxIterations = 0, unconverged = 0;
    uint32_t lastIterations = 0;
    bool lastConverged = true;
    double maxResidual = 0.0, lastResidual = 0.0;
  };

  GpuGate();
  ~GpuGate();  // no longer the route, if a solve that entered it was cut short
  GpuGate(const GpuGate&) = delete;
  GpuGate& operator=(const GpuGate&) = delete;
  // Before the first iteration: go while ||r|| / ||b|| > tolerance (and b != 0); 0 iterations.
  void start(const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations, const Finals& finals = {});
  // After an iteration: counts it while going, and goes on while p.Ap > 0,
  // ||r|| / ||b|| > tolerance and fewer than maxIterations are done. Made
  // by the next gated dispatch's kernel as its last pass (vector_ops.comp's
  // OP_UPDATE_P with GATE, laplace.comp's P_UPDATE; gate_logic.glsl, its
  // buffers at bindings kCheckBindings..+2, its uniforms set at the dispatch).
  static constexpr int kCheckBindings = 10;
  void checkInNext(Slots slots, double tolerance, int maxIterations);
  // The same, by the gate's own kernel (pq, rr: partials to sum first).
  void check(const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations, const Finals& finals);
  // After the true residual's rr: the solve's verdict into the tally.
  void finish(const GpuBuffer& scalars, Slots slots, double tolerance, const Finals& finals = {});
  // Dispatches between enter() and leave() are gated.
  void enter();
  void leave();
  // A gated dispatch of gx x gy groups (dispatchGroups' route while entered).
  void dispatch(unsigned gx, unsigned gy) override;
  // Whether the solve is still going (one host wait).
  bool going() const;
  Tally read() const;  // one host wait
  // The tallies of several gates, in one host wait (their states copied side by side on the device first).
  static std::vector<Tally> read(const std::vector<const GpuGate*>& gates);
  void resetTally();

 private:
  void run(const char* mode, const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations,
           const Finals& finals = {});
  void setTestUniforms(Slots slots, double tolerance, int maxIterations) const;
  void refreshArgs();  // after a new slot: its arguments from the current go flag
  std::map<std::pair<unsigned, unsigned>, unsigned> slotOf_;
  std::vector<uint32_t> base_;  // gx, gy, 1 per slot
  GpuBuffer baseBuffer_, args_, state_;
  size_t capacity_ = 0;
  bool checkInNext_ = false;
  Slots checkSlots_{0, 0, 0};
  double checkTolerance_ = 0.0;
  int checkLimit_ = 0;
};

}  // namespace morphoflow
