#include "gpu/gpu_programs.h"

#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <epoxy/gl.h>

#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_counts.h"
#include "gpu/gpu_reals.h"
#include "gpu/shader_source.h"

namespace morphoflow {

namespace {
// The shader's text with each line `#include "NAME"` replaced by shaders/NAME,
// itself expanded (GLSL has no includes of its own without an extension).
std::string expandIncludes(const std::string& text) {
  std::string out;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    const size_t q = line.find('"');
    if (line.rfind("#include \"", 0) == 0 && q != std::string::npos)
      out += expandIncludes(shaderSource(line.substr(q + 1, line.find('"', q + 1) - q - 1)));
    else
      out += line + "\n";
    at = end + 1;
  }
  return out;
}
}  // namespace

const ComputeProgram& useProgram(const std::string& shader, const std::string& defines) {
  // Kept to the process's end and never freed (no GL call at exit, when the
  // context may be current on no thread).
  static auto& programs = *new std::map<std::string, std::unique_ptr<ComputeProgram>>;
  const std::string key = shader + "\n" + defines;
  auto it = programs.find(key);
  if (it == programs.end())
    it = programs
             .emplace(key, std::make_unique<ComputeProgram>(shader, defines + "\n" + shaderSource("common.glsl"),
                                                            expandIncludes))
             .first;
  it->second->use();
  return *it->second;
}

const ComputeProgram& useProgram(const std::string& shader, const std::string& defines, GpuPrecision real) {
  return useProgram(shader, defines, real, real);
}

const ComputeProgram& useProgram(const std::string& shader, const std::string& defines, GpuPrecision real,
                                 GpuPrecision solution) {
  return useProgram(shader, realDefines(real, solution) + defines);
}

namespace {
double traffic = 0.0;
DispatchRoute* route = nullptr;
}  // namespace

DispatchRoute* routeDispatches(DispatchRoute* to) { return std::exchange(route, to); }

void countGpuTraffic(double bytes) { traffic += bytes; }
double gpuTrafficBytes() { return traffic; }

void dispatchFlat(size_t samples, double bytes) {
  countGpuTraffic(double(samples) * bytes);
  constexpr size_t kGroup = 256, kMaxX = 65535;
  const size_t groups = (samples + kGroup - 1) / kGroup;
  if (groups == 0) return;
  const size_t gx = groups < kMaxX ? groups : kMaxX, gy = (groups + gx - 1) / gx;
  dispatchGroups(unsigned(gx), unsigned(gy));
}

void dispatchGroups(unsigned gx, unsigned gy) {
  if (route) return route->dispatch(gx, gy);
  glDispatchCompute(gx, gy, 1);
  countDispatch();
}

void storageBarrier() { glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT); }

void setUniform(const ComputeProgram& p, const char* name, int v) { glUniform1i(p.uniform(name), v); }
void setUniform(const ComputeProgram& p, const char* name, float v) { glUniform1f(p.uniform(name), v); }
void setUniform(const ComputeProgram& p, const char* name, double v) { setUniformDoubles(p, name, &v, 1); }
void setUniformDoubles(const ComputeProgram& p, const char* name, const double* v, int count, int components) {
  const int at = p.uniform(name);
  if (at < 0) return;
  if (p.singlePrecision(name)) {
    const std::vector<float> f(v, v + size_t(count) * size_t(components));
    if (components == 1) glUniform1fv(at, count, f.data());
    if (components == 2) glUniform2fv(at, count, f.data());
    if (components == 3) glUniform3fv(at, count, f.data());
    return;
  }
  if (components == 1) glUniform1dv(at, count, v);
  if (components == 2) glUniform2dv(at, count, v);
  if (components == 3) glUniform3dv(at, count, v);
}
void setUniform(const ComputeProgram& p, const char* name, const std::array<int, 3>& v) {
  glUniform3i(p.uniform(name), v[0], v[1], v[2]);
}
void setUniformBools(const ComputeProgram& p, const char* name, const std::array<bool, 3>& v) {
  glUniform3i(p.uniform(name), v[0], v[1], v[2]);
}
void setUniform(const ComputeProgram& p, const char* name, const std::array<int, 4>& v) {
  glUniform4i(p.uniform(name), v[0], v[1], v[2], v[3]);
}
void setUniform(const ComputeProgram& p, const char* name, const std::array<float, 3>& v) {
  glUniform3f(p.uniform(name), v[0], v[1], v[2]);
}

}  // namespace morphoflow
