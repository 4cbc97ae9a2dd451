// For the library-level GPU tests: why no OpenGL 4.3 context can be had
// ("" when one can), so a test without one skips with the reason.
#pragma once

#include <string>

#include "gpu/gl_context.h"

inline std::string gpuContextMissing() {
  try {
    morphoflow::GlContext::instance();
    return "";
  } catch (const morphoflow::GpuUnavailable& e) {
    return e.what();
  }
}
