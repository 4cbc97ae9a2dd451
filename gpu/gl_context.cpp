#include "gpu/gl_context.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <fmt/format.h>

namespace morphoflow {

struct GlContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

namespace {

bool hasExtension(EGLDisplay d, const char* name) { return epoxy_has_egl_extension(d, name); }

// The EGL devices, the one with a CUDA id (an NVIDIA GPU) first, then any
// other hardware device; software devices last.
std::vector<EGLDeviceEXT> devicesBestFirst() {
  std::vector<EGLDeviceEXT> out;
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_device_enumeration") ||
      !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_device_query") ||
      !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_device"))
    return out;
  EGLint n = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &n) || n <= 0) return out;
  std::vector<EGLDeviceEXT> all(static_cast<size_t>(n));
  eglQueryDevicesEXT(n, all.data(), &n);
  std::vector<EGLDeviceEXT> cuda, hardware, software;
  for (EGLDeviceEXT d : all) {
    const char* ext = eglQueryDeviceStringEXT(d, EGL_EXTENSIONS);
    const std::string e = ext ? ext : "";
    EGLAttrib id = 0;
    if (e.find("EGL_NV_device_cuda") != std::string::npos && eglQueryDeviceAttribEXT(d, EGL_CUDA_DEVICE_NV, &id))
      cuda.push_back(d);
    else if (e.find("EGL_MESA_device_software") != std::string::npos)
      software.push_back(d);
    else
      hardware.push_back(d);
  }
  for (auto* v : {&cuda, &hardware, &software}) out.insert(out.end(), v->begin(), v->end());
  return out;
}

// Initialises `d` and creates a 4.3 core context current with no surface; false if it cannot.
bool makeContext(EGLDisplay d, GlContext::Egl* egl) {
  EGLint major = 0, minor = 0;
  if (d == EGL_NO_DISPLAY || !eglInitialize(d, &major, &minor)) return false;
  if (!hasExtension(d, "EGL_KHR_surfaceless_context") || !eglBindAPI(EGL_OPENGL_API)) {
    eglTerminate(d);
    return false;
  }
  // Robust access with lose-on-reset first (EGL 1.5), so a lost device
  // becomes GL_CONTEXT_LOST at the next check rather than undefined
  // behaviour; without it, the plain context.
  const EGLint robust[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3,
                           EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                           EGL_CONTEXT_OPENGL_ROBUST_ACCESS, EGL_TRUE,
                           EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY, EGL_LOSE_CONTEXT_ON_RESET,
#ifndef NDEBUG
                           EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE,
#endif
                           EGL_NONE};
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
#ifndef NDEBUG
                            EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE,
#endif
                            EGL_NONE};
  EGLConfig config = nullptr;
  if (!hasExtension(d, "EGL_KHR_no_config_context")) {
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(d, want, &config, 1, &count) || count < 1) {
      eglTerminate(d);
      return false;
    }
  }
  EGLContext c = major > 1 || minor >= 5 ? eglCreateContext(d, config, EGL_NO_CONTEXT, robust) : EGL_NO_CONTEXT;
  if (c == EGL_NO_CONTEXT) c = eglCreateContext(d, config, EGL_NO_CONTEXT, attribs);
  if (c == EGL_NO_CONTEXT || !eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
    if (c != EGL_NO_CONTEXT) eglDestroyContext(d, c);
    eglTerminate(d);
    return false;
  }
  egl->display = d;
  egl->context = c;
  return true;
}

#ifndef NDEBUG
void GLAPIENTRY debugMessage(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                             const void*) {
  if (severity != GL_DEBUG_SEVERITY_NOTIFICATION)
    std::fprintf(stderr, "GL %s: %s\n", type == GL_DEBUG_TYPE_ERROR ? "error" : "debug", message);
}
#endif

}  // namespace

GlContext& GlContext::instance() {
  static GlContext context;
  context.makeCurrent();
  return context;
}

void GlContext::makeCurrent() {
  if (holder_.load() == std::this_thread::get_id()) return;
  std::lock_guard<std::mutex> lk(mutex_);
  if (holder_.load() != std::thread::id())
    throw GpuError("the GPU's context is current on another thread: one thread at a time uses the GPU");
  if (!eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context))
    throw GpuError("eglMakeCurrent failed on this thread (EGL error " + std::to_string(eglGetError()) + ")");
  holder_ = std::this_thread::get_id();
}

void GlContext::release() {
  std::lock_guard<std::mutex> lk(mutex_);
  if (holder_.load() != std::this_thread::get_id()) return;
  eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  holder_ = std::thread::id();
}

GlContext::GlContext() : egl_(std::make_unique<Egl>()) {
  if (!epoxy_has_egl()) throw GpuUnavailable("no EGL library (libEGL.so.1) could be loaded");
  // Without a vendor library (libglvnd found none) the platform displays'
  // entry points are missing, and calling one would abort the process.
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_base"))
    throw GpuUnavailable("the EGL library has no vendor that offers platform displays (EGL_EXT_platform_base): check "
                         "__EGL_VENDOR_LIBRARY_FILENAMES and __EGL_VENDOR_LIBRARY_DIRS, or install libegl-mesa0");
  for (EGLDeviceEXT dev : devicesBestFirst())
    if (makeContext(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, dev, nullptr), egl_.get())) {
      platform_ = "EGL device";
      break;
    }
  if (egl_->context == EGL_NO_CONTEXT && epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless") &&
      makeContext(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), egl_.get()))
    platform_ = "Mesa surfaceless";
  if (egl_->context == EGL_NO_CONTEXT)
    throw GpuUnavailable("no OpenGL 4.3 core context: neither an EGL device nor Mesa's surfaceless platform offers one "
                         "(install libegl-mesa0 and libgl1-mesa-dri for llvmpipe)");
  if (epoxy_gl_version() < 43)
    throw GpuUnavailable(fmt::format("OpenGL {:.1f} only; compute shaders need 4.3", epoxy_gl_version() / 10.0));
  holder_ = std::this_thread::get_id();  // (makeContext made it current here)
  renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  version_ = reinterpret_cast<const char*>(glGetString(GL_VERSION));
#ifndef NDEBUG
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(debugMessage, nullptr);
#endif
}

GlContext::~GlContext() {
  if (egl_->context != EGL_NO_CONTEXT) {
    eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(egl_->display, egl_->context);
    eglTerminate(egl_->display);
  }
}

size_t GlContext::availableBytes() const {
  if (!epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) return 0;
  GLint kib = 0;
  glGetIntegerv(0x9049, &kib);  // GPU_MEMORY_INFO_CURRENT_AVAILABLE_VIDMEM_NVX, in KiB
  glGetError();
  return size_t(std::max(kib, 0)) * 1024;
}

void GlContext::check(const char* what) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  if (e == GL_CONTEXT_LOST)
    throw GpuError(fmt::format("the GPU device was lost (a reset: a driver or GPU fault, or the device removed) in {}; "
                               "the last checkpoint is intact: continue with --resume",
                               what));
  throw GpuError(fmt::format("OpenGL error 0x{:04x} ({}) in {}", e,
                             e == GL_OUT_OF_MEMORY       ? "out of GPU memory"
                             : e == GL_INVALID_OPERATION ? "invalid operation"
                                                         : "invalid value or enum",
                             what));
}

GpuInfo gpuInfo() {
  GpuInfo g;
  try {
    const GlContext& c = GlContext::instance();
    g = {true, c.renderer(), c.version(), c.platform(), ""};
  } catch (const std::exception& e) {
    g.reason = e.what();
  }
  return g;
}

void recordGlContext(nlohmann::json* run) {
  const GlContext& c = GlContext::instance();
  (*run)["gl_renderer"] = c.renderer();
  (*run)["gl_version"] = c.version();
  (*run)["gl_platform"] = c.platform();
}

}  // namespace morphoflow
