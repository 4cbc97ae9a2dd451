// The validations run the shipped scenes in process, through the libraries
// the command line uses (run/run_options.h), not by starting the binary.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "run/run_options.h"

namespace morphoflow::testing {

// `morphoflow run SCENE --set ... --quiet --out OUT`; returns its exit status.
inline int runInProcess(const std::string& scene, std::vector<std::string> overrides, const std::filesystem::path& out) {
  RunOptions o;
  o.scene = scene;
  o.overrides = std::move(overrides);
  o.out = out.string();
  o.quiet = true;
  return runScene(o);
}

}  // namespace morphoflow::testing
