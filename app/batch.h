// `morphoflow batch`: several scenes, each into OUT/<scene file stem>.
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

struct BatchOptions {
  std::vector<std::string> scenes;
  std::string shard;        // "I/N": every N-th scene from the I-th (0-based)
  int jobs = 1;             // scenes run at once
  std::string out = "out";
};

// Validates every scene of the shard first, then runs them; returns the
// worst exit status. Throws UserError on a bad option or scene.
int runBatch(const BatchOptions& options);

}  // namespace morphoflow
