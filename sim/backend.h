// --backend: TBB tasks, one thread (the coupled step's serial schedule), or
// OpenGL compute.
#pragma once

#include <string>

namespace morphoflow {

enum class Backend { TBB, Serial, Gpu };
// "tbb", "serial" or "gpu"; std::invalid_argument for any other name.
Backend backendNamed(const std::string& name);

}  // namespace morphoflow
