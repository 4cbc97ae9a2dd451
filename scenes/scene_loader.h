// Reads a scene file (TOML, toml++), applies --set overrides, and checks
// every key: unknown keys, wrong types and out-of-range values raise a
// UserError naming file:line:column, the key, what was expected and the
// nearest valid key.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "scenes/scene.h"

namespace morphoflow {

// `overrides` are "key.path=value" strings, value in TOML syntax
// (e.g. "fluid.reynolds=400", "grid.resolution=[256,256]").
Scene loadScene(const std::string& path, const std::vector<std::string>& overrides = {});

// The two halves of loadScene: the file's text (only a regular file, at most
// kMaxSceneBytes), and the scene it describes (`path` names it in errors and
// is where relative image paths start).
constexpr uintmax_t kMaxSceneBytes = 4u << 20;
std::string readSceneText(const std::string& path);
Scene parseScene(const std::string& text, const std::string& path, const std::vector<std::string>& overrides = {});

// The scene as it stands at time t of its timeline (scenes/timeline.h):
// keyed values at t, the obstacles and strokes that exist then; no timeline.
Scene sceneAt(const Scene& scene, double t);

// Levenshtein distance, for "did you mean" suggestions.
int editDistance(const std::string& a, const std::string& b);

}  // namespace morphoflow
