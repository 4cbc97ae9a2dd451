#include "gpu/gpu_gate.h"

#include <algorithm>
#include <cstring>

#include <epoxy/gl.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_counts.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

namespace {
constexpr size_t kStateBytes = 8 * sizeof(uint32_t) + 2 * sizeof(double);
}  // namespace

GpuGate::GpuGate() : state_(kStateBytes) { resetTally(); }

GpuGate::~GpuGate() {
  DispatchRoute* now = routeDispatches(nullptr);
  if (now != this) routeDispatches(now);
}

void GpuGate::enter() { routeDispatches(this); }
void GpuGate::leave() { routeDispatches(nullptr); }

void GpuGate::run(const char* mode, const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations,
                  const Finals& finals) {
  DispatchRoute* was = routeDispatches(nullptr);  // the gate's own kernel is not gated
  const ComputeProgram& p = useProgram("gate.comp", std::string("#define ") + mode);
  setTestUniforms(slots, tolerance, maxIterations);
  glUniform2i(p.uniform("finals"), finals.slots[0], finals.slots[1]);
  setUniform(p, "groups", int(finals.groups));
  scalars.bind(0);
  (finals.partials ? *finals.partials : state_).bind(4);
  (baseBuffer_.bytes() ? baseBuffer_ : state_).bind(1);
  (args_.bytes() ? args_ : state_).bind(2);
  state_.bind(3);
  glDispatchCompute(1, 1, 1);
  countDispatch();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
  routeDispatches(was);
}

void GpuGate::setTestUniforms(Slots slots, double tolerance, int maxIterations) const {
  GLint program = 0;  // gate_logic.glsl's uniforms, on the current program
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  const auto at = [&](const char* name) { return glGetUniformLocation(GLuint(program), name); };
  glUniform3i(at("gateSlot"), slots.bb, slots.rr, slots.pq);
  glUniform1d(at("gateTol"), tolerance);
  glUniform1i(at("gateLimit"), maxIterations);
  glUniform1i(at("gateCount"), GLint(base_.size() / 3));
}

void GpuGate::start(const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations, const Finals& finals) {
  run("MODE_START", scalars, slots, tolerance, maxIterations, finals);
}
void GpuGate::finish(const GpuBuffer& scalars, Slots slots, double tolerance, const Finals& finals) {
  run("MODE_FINISH", scalars, slots, tolerance, 0, finals);
}

void GpuGate::checkInNext(Slots slots, double tolerance, int maxIterations) {
  checkInNext_ = true;
  checkSlots_ = slots;
  checkTolerance_ = tolerance;
  checkLimit_ = maxIterations;
}

void GpuGate::check(const GpuBuffer& scalars, Slots slots, double tolerance, int maxIterations, const Finals& finals) {
  run("MODE_CHECK", scalars, slots, tolerance, maxIterations, finals);
}

void GpuGate::refreshArgs() {
  // Called in the middle of another kernel's dispatch: its program and the
  // bindings the gate's kernel takes are put back after.
  GLint program = 0, bound[5] = {0, 0, 0, 0, 0};
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  for (GLuint i = 0; i < 5; ++i) glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, i, &bound[i]);
  run("MODE_REFRESH", state_, Slots{0, 0, 0}, 0.0, 0);
  glUseProgram(GLuint(program));
  for (GLuint i = 0; i < 5; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, GLuint(bound[i]));
}

void GpuGate::dispatch(unsigned gx, unsigned gy) {
  auto it = slotOf_.find({gx, gy});
  if (it == slotOf_.end()) {
    // A new size: its base groups, and its arguments from the go flag as it is now.
    it = slotOf_.emplace(std::make_pair(gx, gy), unsigned(base_.size() / 3)).first;
    base_.insert(base_.end(), {gx, gy, 1u});
    if (base_.size() * sizeof(uint32_t) > capacity_) {
      capacity_ = std::max<size_t>(64 * 3 * sizeof(uint32_t), 2 * base_.size() * sizeof(uint32_t));
      baseBuffer_ = GpuBuffer(capacity_);
      args_ = GpuBuffer(capacity_);
    }
    baseBuffer_.upload(base_.data(), base_.size() * sizeof(uint32_t));
    refreshArgs();
  }
  const bool checks = checkInNext_;
  if (checks) {  // the kernel makes the check: the gate's buffers as they are now
    setTestUniforms(checkSlots_, checkTolerance_, checkLimit_);
    baseBuffer_.bind(kCheckBindings);
    args_.bind(kCheckBindings + 1);
    state_.bind(kCheckBindings + 2);
    checkInNext_ = false;
  }
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args_.id());
  glDispatchComputeIndirect(GLintptr(it->second * 3 * sizeof(uint32_t)));
  countDispatch();
  if (checks) glMemoryBarrier(GL_COMMAND_BARRIER_BIT);  // its arguments, for the next dispatches
}

bool GpuGate::going() const { return state_.read<uint32_t>(1)[0] != 0u; }

namespace {
GpuGate::Tally tallyOf(const uint8_t* raw) {
  uint32_t u[8];
  std::memcpy(u, raw, sizeof u);
  GpuGate::Tally t;
  t.solves = u[2], t.iterations = u[3], t.maxIterations = u[4], t.unconverged = u[5];
  t.lastIterations = u[6], t.lastConverged = u[7] != 0u;
  std::memcpy(&t.maxResidual, raw + 32, sizeof(double));
  std::memcpy(&t.lastResidual, raw + 40, sizeof(double));
  return t;
}
}  // namespace

GpuGate::Tally GpuGate::read() const {
  std::vector<uint8_t> raw(kStateBytes);
  state_.download(raw.data(), kStateBytes);
  return tallyOf(raw.data());
}

std::vector<GpuGate::Tally> GpuGate::read(const std::vector<const GpuGate*>& gates) {
  GpuBuffer all(gates.size() * kStateBytes);
  for (size_t k = 0; k < gates.size(); ++k) all.copyFrom(gates[k]->state_, kStateBytes, 0, k * kStateBytes);
  std::vector<uint8_t> raw(gates.size() * kStateBytes);
  all.download(raw.data(), raw.size());
  std::vector<Tally> tallies;
  for (size_t k = 0; k < gates.size(); ++k) tallies.push_back(tallyOf(raw.data() + k * kStateBytes));
  return tallies;
}

void GpuGate::resetTally() {
  std::vector<uint8_t> zero(kStateBytes, 0);
  const uint32_t go = 1;
  std::memcpy(zero.data(), &go, sizeof go);
  state_.upload(zero.data(), kStateBytes);
}

}  // namespace morphoflow
