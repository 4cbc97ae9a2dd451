// morphoflow.studio(): the studio (docs/studio.md) served from Python.
#pragma once

#include <functional>
#include <string>

#include <pybind11/pybind11.h>

namespace morphoflow {

// Adds morphoflow.Studio and morphoflow.studio(); `executable` names the
// morphoflow binary the studio's Render starts.
void bindStudio(pybind11::module_& m, std::function<std::string()> executable);

}  // namespace morphoflow
