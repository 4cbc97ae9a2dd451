// The runs of a batch or sweep, planned before any starts: each its scene,
// its overrides and its own output folder.
#pragma once

#include <string>
#include <vector>

#include "scenes/vary.h"

namespace morphoflow {

struct BatchRun {
  std::string scene;                   // the scene file
  std::string folder;                  // under the batch's --out, unique in the batch
  std::vector<std::string> overrides;  // --set, then the sweep's values
  std::vector<std::string> labels;     // sweep: each varied key's value
};

struct BatchPlan {
  std::string kind;               // "batch" or "sweep"
  std::vector<std::string> keys;  // sweep: the varied keys
  std::vector<BatchRun> runs;
  std::string id;                 // hash of the kind, keys, scenes and folders: which batch a folder holds
};

// A scene listed twice is refused; scenes with the same file name get the
// folders NAME, NAME-2, NAME-3 in the order listed.
BatchPlan planBatch(const std::vector<std::string>& scenes, const std::vector<std::string>& sets);
// Every combination of the values, each into "key=value,key=value".
BatchPlan planSweep(const std::string& scene, const std::vector<Vary>& varies, const std::vector<std::string>& sets);

// "I/N" -> {I, N}; throws UserError naming --shard.
std::pair<int, int> parseShard(const std::string& text);

}  // namespace morphoflow
