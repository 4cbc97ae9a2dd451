// Checkpoints: a run's complete state in DIR/checkpoints/NNNNNNNNNN.ckpt
// (NNNNNNNNNN: the step), so that --resume continues it bit for bit. A file
// is "MFCKPT01", a JSON header (scene hash and resolved scene, step, time,
// the driver's own state), the simulation's state, and an xxHash64 of all
// that; it is written atomically, and the two newest are kept.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/state_archive.h"

namespace morphoflow {

struct Checkpoint {
  std::filesystem::path file;
  nlohmann::json header;
  std::string state;
};

// The folder and file of the checkpoint at `step`.
std::filesystem::path checkpointDir(const std::filesystem::path& out);
std::filesystem::path checkpointFile(const std::filesystem::path& out, long step);

// Writes a checkpoint of the state `save` puts (called twice: to measure
// it, then to stream it into the file, so it is never copied whole) and
// removes all but the two newest. Returns the file.
std::filesystem::path writeCheckpoint(const std::filesystem::path& out, long step, const nlohmann::json& header,
                                      const std::function<void(StateWriter*)>& save);

// The same into one file (written atomically; nothing else removed).
void writeCheckpointFile(const std::filesystem::path& file, const nlohmann::json& header,
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
