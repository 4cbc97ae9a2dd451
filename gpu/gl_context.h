// A headless OpenGL 4.3+ core context through EGL, with no window and no X
// server: the EGL device platform first (a hardware GPU; on NVIDIA the
// device that reports EGL_CUDA_DEVICE_NV), then Mesa's surfaceless platform
// (llvmpipe when there is no GPU). One context per process, current on one
// thread at a time: the thread that last called instance().
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <mutex>

#include <nlohmann/json.hpp>

namespace morphoflow {

// No usable context (no EGL, no GL 4.3): the reason, for exit 2 or a skipped test.
class GpuUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A GL call that failed (a shader that does not compile, out of memory).
class GpuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class GlContext {
 public:
  // The process's context, created on first use (throws GpuUnavailable) and
  // made current on the calling thread (throws GpuError while another thread
  // holds it: one thread at a time uses the GPU).
  static GlContext& instance();
  // Lets go of the context on the calling thread, so that another thread's
  // instance() may take it (the studio steps on a thread of its own).
  void release();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;
  ~GlContext();

  const std::string& renderer() const { return renderer_; }
  const std::string& version() const { return version_; }
  const std::string& platform() const { return platform_; }  // "EGL device" or "Mesa surfaceless"
  // Free device memory in bytes where the driver says (NVIDIA's
  // GL_NVX_gpu_memory_info), else 0 (unknown: llvmpipe uses the CPU's memory).
  size_t availableBytes() const;
  // The glGetError state after `what`, as a GpuError.
  static void check(const char* what);

 private:
  GlContext();

 public:
  struct Egl;  // the display and context (gl_context.cpp)

 private:
  void makeCurrent();

  std::unique_ptr<Egl> egl_;
  std::mutex mutex_;
  std::atomic<std::thread::id> holder_{};  // the thread it is current on (none: released)
  std::string renderer_, version_, platform_;
};

// The GL renderer and version ("llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core Profile) Mesa 22.3.6"),
// or the reason there is no context.
struct GpuInfo {
  bool available = false;
  std::string renderer, version, platform, reason;
};
GpuInfo gpuInfo();

// run.json: gl_renderer, gl_version, gl_platform of the context in use.
void recordGlContext(nlohmann::json* run);

}  // namespace morphoflow
