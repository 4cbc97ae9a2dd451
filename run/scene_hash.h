// The settings hash of a resolved scene (xxHash64 of its JSON form), kept in
// run.json, checkpoints and VDB metadata: --resume continues only the same
// scene, and a batch skips scenes already completed with the same settings.
#pragma once

#include <string>
#include <vector>

#include "scenes/scene.h"

namespace morphoflow {

// 16 hex digits.
std::string sceneHash(const Scene& scene);
std::string hashHex(const void* data, size_t bytes);
// The keys (dotted paths) whose values differ between two resolved scenes
// (JSON text), for "resuming with a changed scene"; none when either is not
// a JSON table.
std::vector<std::string> changedKeys(const std::string& jsonA, const std::string& jsonB);

}  // namespace morphoflow
