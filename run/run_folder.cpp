#include "run/run_folder.h"

#include <fstream>
#include <regex>

#include <nlohmann/json.hpp>

#include "run/output_kinds.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// Removes the regular files in `dir` whose names match `pattern`, then `dir`
// itself if that left it empty.
int removeMatching(const fs::path& dir, const std::regex& pattern) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) return 0;
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (fs::is_regular_file(e.symlink_status(ec)) && std::regex_match(name, pattern) && fs::remove(e.path(), ec)) ++n;
  }
  if (fs::is_empty(dir, ec)) fs::remove(dir, ec);
  return n;
}

}  // namespace

int removeEarlierRun(const fs::path& out, const std::string& videoStem) {
  const std::string tmp = R"((\.tmp(\.[a-z]+)?|\.part)?)";
  int n = 0;
  for (const OutputKind& kind : kOutputKinds)
    n += removeMatching(out / kind.folder, std::regex(std::string("(") + kind.pattern + ")" + tmp));
  // The earlier run's video may have had another name.
  std::string earlierVideo;
  try {
    std::error_code ec;
    std::ifstream in;
    if (fs::is_regular_file(fs::symlink_status(out / "run.json", ec))) in.open(out / "run.json");  // never a pipe
    if (in) {
      const nlohmann::json j = nlohmann::json::parse(in);
      if (j.contains("video") && j["video"].contains("file"))
        earlierVideo = fs::path(j["video"]["file"].get<std::string>()).stem().string();
    }
  } catch (const std::exception&) {
  }
  std::string top = std::string("((") + kTopLevelFiles + ")" + tmp + ")";
  for (const std::string& stem : {videoStem, earlierVideo})
    if (!stem.empty()) top += "|" + std::regex_replace(stem, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
                              R"((\.mp4(\.part)?|\.ffmpeg\.log))";
  std::error_code ec;
  const std::regex topPattern(top);
  for (const auto& e : fs::directory_iterator(out, ec)) {
    const std::string name = e.path().filename().string();
    if (fs::is_regular_file(e.symlink_status(ec)) && std::regex_match(name, topPattern) && fs::remove(e.path(), ec))
      ++n;
  }
  return n;
}

}  // namespace morphoflow
