// Whole-file writes for run outputs: a temporary name, then a rename, so a
// crash never leaves a half-written file under the final name.
#pragma once

#include <filesystem>
#include <string>

namespace morphoflow {

void writeTextFile(const std::filesystem::path& path, const std::string& text);

}  // namespace morphoflow
