// The flat compute programs (shaders/common.glsl prepended): each compiled
// once per process for its #defines, and dispatched one invocation a sample.
#pragma once

#include <array>
#include <cstddef>
#include <string>

#include "core/backend.h"

namespace morphoflow {

class ComputeProgram;

// The program of shaders/SHADER with `defines` (lines of #define), made
// current (glUseProgram).
const ComputeProgram& useProgram(const std::string& shader, const std::string& defines);
// The same with the real vectors' types defined (gpu_reals.h's REAL, and
// XREAL: `solution`'s, `real`'s when not given).
const ComputeProgram& useProgram(const std::string& shader, const std::string& defines, GpuPrecision real);
const ComputeProgram& useProgram(const std::string& shader, const std::string& defines, GpuPrecision real,
                                 GpuPrecision solution);
// Dispatches the current program over `samples` invocations, each of which
// must read or write `bytes` of the buffers at least once (the traffic model
// the benchmarks divide by time: a lower bound of the memory traffic).
void dispatchFlat(size_t samples, double bytes);
// Where dispatches go while it is set: a solve's gate (gpu_gate.h) makes
// every dispatch indirect.
class DispatchRoute {
 public:
  virtual void dispatch(unsigned gx, unsigned gy) = 0;

 protected:
  ~DispatchRoute() = default;
};
// Sets the route dispatchGroups takes (null: glDispatchCompute); returns the
// one set before.
DispatchRoute* routeDispatches(DispatchRoute* route);
// Dispatches gx x gy groups of the current program, through the route if one is set.
void dispatchGroups(unsigned gx, unsigned gy);
// Counts dispatched traffic (dispatchFlat's, and programs that call it directly).
void countGpuTraffic(double bytes);
// The traffic counted since the process started.
double gpuTrafficBytes();
// The barrier between a program and the next one that reads what it wrote
// through storage buffers.
void storageBarrier();

// Uniform setters on the current program (a name the compiler removed is ignored).
void setUniform(const ComputeProgram& p, const char* name, int v);
void setUniform(const ComputeProgram& p, const char* name, float v);
// A double's value goes to a float uniform rounded (a REAL one in float), to a double one as it is.
void setUniform(const ComputeProgram& p, const char* name, double v);
// `count` values of `components` doubles each (an array of double, dvec2 or dvec3, or their float forms).
void setUniformDoubles(const ComputeProgram& p, const char* name, const double* v, int count, int components = 1);
void setUniform(const ComputeProgram& p, const char* name, const std::array<int, 3>& v);
void setUniformBools(const ComputeProgram& p, const char* name, const std::array<bool, 3>& v);
void setUniform(const ComputeProgram& p, const char* name, const std::array<int, 4>& v);
void setUniform(const ComputeProgram& p, const char* name, const std::array<float, 3>& v);

}  // namespace morphoflow
