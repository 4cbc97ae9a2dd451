#include "gpu/gpu_copy_bandwidth.h"

#include <algorithm>
#include <chrono>
#include <vector>

#include <epoxy/gl.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_buffer.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

double measureCopyBandwidth(size_t bytes) {
  const size_t vec4s = bytes / 16;
  GpuBuffer src(vec4s * 16), dst(vec4s * 16);
  src.zero();
  std::vector<double> seconds;
  for (int k = 0; k < 6; ++k) {
    const ComputeProgram& p = useProgram("copy.comp", "");
    setUniform(p, "n", int(vec4s));
    src.bind(0);
    dst.bind(1);
    glFinish();
    const auto t0 = std::chrono::steady_clock::now();
    dispatchFlat(vec4s, 0.0);  // (not the suites' traffic)
    glFinish();
    if (k > 0) seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(seconds.begin(), seconds.begin() + 2, seconds.end());
  return 2.0 * double(vec4s * 16) / seconds[2] * 1e-9;
}

}  // namespace morphoflow
