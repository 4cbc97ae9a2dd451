// The studio's record of a session: the scene file's tree with every edit
// written into it as the scene's own timeline (scenes/timeline.h), each at
// the time of the step it took effect at. Its text is what "Save" returns,
// and `morphoflow run` of that text replays the session bit for bit.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scenes/scene.h"

namespace morphoflow {

class EditLog {
 public:
  // The scene file's text; `path` names it in messages and is where its
  // relative paths start. Throws UserError when it does not read.
  EditLog(const std::string& text, const std::string& path);

  // Each edit below is checked by reading the scene with it (the reader's
  // UserError, and nothing changed, when it does not read) and recorded at
  // time t.
  // A steerable key (scenes/timeline.h) to a number or an array of numbers.
  void set(const std::string& key, const nlohmann::json& value, double t);
  // A paint edit: {"kind": "deposit" | "stroke" | "source" | "obstacle", ...}
  // adds an element; {"kind": "move", "target": "obstacles.N" | "sources.N",
  // "center": [...]} moves one; {"kind": "erase", "target": ...} ends one.
  void paint(const nlohmann::json& edit, double t);
  // Every edit as if made at t = 0 (the studio's reset): keyed values take
  // their last value, ended elements go, deposits go.
  void collapse();

  std::string text() const;
  const Scene& scene() const { return scene_; }
  const std::string& path() const { return path_; }

 private:
  void commit(std::string text);

  std::string path_, text_;
  Scene scene_;
};

}  // namespace morphoflow
