// Every kind of file a run writes into its output folder, in one list: the
// subfolder and the names' pattern (a regex). The writers take their
// folders from here, and a new run's cleanup (run_folder.h) removes exactly
// these, so no kind of output can be left over from an earlier run.
#pragma once

#include <array>

namespace morphoflow {

struct OutputKind {
  const char* folder;   // inside the output folder
  const char* pattern;  // the file names a run writes there
};

inline constexpr OutputKind kFrameFiles{"frames", R"(\d{6}\.(png|exr))"};
inline constexpr OutputKind kFieldFiles{"fields", R"(\d{6}\.exr)"};
inline constexpr OutputKind kNormalMapFiles{"normals", R"(\d{6}\.png)"};
inline constexpr OutputKind kHeightFiles{"height", R"(\d{6}\.exr)"};
inline constexpr OutputKind kVdbFiles{"vdb", R"(.+\.\d{6}\.(vdb|nvdb))"};
inline constexpr OutputKind kCheckpointFiles{"checkpoints", R"(\d{10}\.ckpt)"};
inline constexpr OutputKind kProfileFiles{"profiles", R"((u_vertical|v_horizontal)_centerline\.csv)"};

inline constexpr std::array<OutputKind, 7> kOutputKinds = {kFrameFiles, kFieldFiles,      kNormalMapFiles, kHeightFiles,
                                                           kVdbFiles,   kCheckpointFiles, kProfileFiles};

// The files in the output folder itself: the records, the force probe's
// table (the video is named after the scene, and handled by the cleanup).
inline constexpr const char* kTopLevelFiles = R"(run\.json|log\.txt|forces\.csv)";

}  // namespace morphoflow
