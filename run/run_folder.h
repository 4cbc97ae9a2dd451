// The output folder of a run. A new run into a folder that holds an earlier
// run's outputs removes those first (only files a run writes, by their
// names: every kind in output_kinds.h, and the video), so two runs' files
// never mix; anything else in the folder is left alone. --resume keeps them and continues.
#pragma once

#include <filesystem>
#include <string>

namespace morphoflow {

// Removes an earlier run's outputs from `out`; returns how many files went.
int removeEarlierRun(const std::filesystem::path& out, const std::string& videoStem);

}  // namespace morphoflow
