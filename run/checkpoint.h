// Checkpoints: a run's complete state in DIR/checkpoints/NNNNNNNNNN.ckpt
// (NNNNNNNNNN: the step), so that --resume continues it bit for bit. A file
// is "MFCKPT01", a JSON header (scene hash and resolved scene, step, time,
// the driver's own state), the simulation's state, and an xxHash64 of all
// that; it is written atomically, and the two newest are kept.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/state_archive.h"
#include "run/version.h"

namespace morphoflow {

// A checkpoint's header (JSON in the file). The run driver writes and reads
// every key; Simulation.save (python/) writes no outputs and adds `python`,
// the scene as the module was given it.
struct CheckpointHeader {
  std::string version = kVersion;  // the morphoflow that wrote it
  std::string sceneHash, scene;   // the settings hash; the resolved scene (JSON text)
  long step = 0;
  double time = 0.0;
  long lastFrame = -1;            // the last frame written (-1: none)
  nlohmann::json sinks = nlohmann::json::array();  // each output's state: whole numbers by name
  std::string log;                // the run's log so far
  uintmax_t checkpointBytes = 0;  // what the run's checkpoints took before this one
  struct PythonScene {
    std::string text, path;
    std::vector<std::string> overrides;
  };
  std::optional<PythonScene> python;

  nlohmann::json toJson() const;
  // A header that readCheckpoint has checked (keys and types).
  static CheckpointHeader fromJson(const nlohmann::json& h);
};

struct Checkpoint {
  std::filesystem::path file;
  CheckpointHeader header;
  std::string state;
};

// The folder and file of the checkpoint at `step`.
std::filesystem::path checkpointDir(const std::filesystem::path& out);
std::filesystem::path checkpointFile(const std::filesystem::path& out, long step);

// Writes a checkpoint of the state `save` puts (called twice: to measure
// it, then to stream it into the file, so it is never copied whole) and
// removes all but the two newest. Returns the file.
std::filesystem::path writeCheckpoint(const std::filesystem::path& out, long step, const CheckpointHeader& header,
                                      const std::function<void(StateWriter*)>& save);

// The same into one file (written atomically; nothing else removed).
void writeCheckpointFile(const std::filesystem::path& file, const CheckpointHeader& header,
                         const std::function<void(StateWriter*)>& save);

// Reads one checkpoint; throws UserError naming the file when it is cut
// short, corrupted or not a checkpoint.
Checkpoint readCheckpoint(const std::filesystem::path& file);

// Whether `out` holds any checkpoint file (intact or not).
bool hasCheckpoint(const std::filesystem::path& out);

// The newest intact checkpoint under `out`; each damaged one on the way is
// reported through `warn`. Throws UserError when there is none.
Checkpoint latestCheckpoint(const std::filesystem::path& out, const std::function<void(const std::string&)>& warn);

}  // namespace morphoflow
