// The GLSL compute shaders of gpu/shaders/, embedded in the binary at build
// time (gpu/embed_shaders.cmake): never read from disk at run time.
#pragma once

#include <string>

namespace morphoflow {

// The source of shaders/NAME (e.g. "rd_explicit.comp"); throws std::logic_error for an unknown name.
const std::string& shaderSource(const std::string& name);

}  // namespace morphoflow
