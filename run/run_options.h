// Options of `morphoflow run`, as given on the command line.
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct RunOptions {
  std::string scene;
  std::vector<std::string> overrides;  // --set key=value
  std::string out = "out";
  std::string backend = "tbb";
  int threads = 0;                     // 0 = all cores
  int firstFrame = 0, lastFrame = -1;  // --frames A:B (inclusive; -1 = to the end)
  bool quiet = false;
  bool resume = false;                 // continue from the newest intact checkpoint in `out`
  bool force = false;                  // resume even though the scene changed
};

// Runs one scene; returns the process exit status. Throws UserError on bad input.
int runScene(const RunOptions& options);

}  // namespace morphoflow
