#include "batch/batch_plan.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "run/scene_hash.h"
#include "core/error.h"
#include "core/number_text.h"
#include "core/output_file.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

constexpr size_t kMaxRuns = 100000;

// Which runs, into which folders (not their settings: a batch resumed with
// another --set, or with an edited scene, reruns what changed).
void identify(BatchPlan* p) {
  nlohmann::json j = {{"kind", p->kind}, {"keys", p->keys}, {"runs", nlohmann::json::array()}};
  for (const BatchRun& r : p->runs) j["runs"].push_back({r.scene, r.folder});
  const std::string text = j.dump();
  p->id = hashHex(text.data(), text.size());
}

// A folder name from sweep labels: no separators, no leading dot.
std::string folderPart(const std::string& s) {
  std::string out;
  for (char c : s)
    out +=
        (std::isalnum(static_cast<unsigned char>(c)) || std::string("._+-[]").find(c) != std::string::npos) ? c : '_';
  return out;
}

}  // namespace

BatchPlan planBatch(const std::vector<std::string>& scenes, const std::vector<std::string>& sets) {
  if (scenes.empty()) throw UserError({"batch", 0, 0}, "", "no scenes given", "list one or more scene files");
  if (scenes.size() > kMaxRuns) throw UserError({"batch", 0, 0}, "", fmt::format("more than {} scenes", kMaxRuns));
  BatchPlan p;
  p.kind = "batch";
  std::map<std::string, std::string> seen;  // canonical path -> as listed
  std::set<std::string> folders;
  for (const std::string& s : scenes) {
    std::error_code ec;
    const std::string canonical = fs::weakly_canonical(fs::absolute(s, ec), ec).string();
    if (auto [it, fresh] = seen.emplace(canonical, s); !fresh)
      throw UserError({s, 0, 0}, "", "the scene is listed twice in the batch (also as " + it->second + ")",
                      "list each scene once; to run a scene with other settings, use sweep or a copy of the file");
    const std::string stem = safeFileStem(fs::path(s).stem().string());
    std::string folder = stem;
    for (int n = 2; !folders.insert(folder).second; ++n) folder = fmt::format("{}-{}", stem, n);
    p.runs.push_back({s, folder, sets, {}});
  }
  identify(&p);
  return p;
}

BatchPlan planSweep(const std::string& scene, const std::vector<Vary>& varies, const std::vector<std::string>& sets) {
  if (varies.empty()) throw UserError({"sweep", 0, 0}, "", "nothing to vary", "add --vary key=start:stop:count");
  BatchPlan p;
  p.kind = "sweep";
  std::set<std::string> keys;
  for (const Vary& v : varies) {
    if (!keys.insert(v.key).second)
      throw UserError({"--vary " + v.key, 0, 0}, "", "the key is varied twice", "give each key one --vary");
    for (const std::string& s : sets)
      if (s.substr(0, s.find('=')) == v.key)
        throw UserError({"--set " + s, 0, 0}, "", "the key is also varied", "drop the --set or the --vary of " + v.key);
    p.keys.push_back(v.key);
  }
  size_t total = 1;
  for (const Vary& v : varies)
    if ((total *= v.values.size()) > kMaxRuns)
      throw UserError({"sweep", 0, 0}, "", fmt::format("the sweep has more than {} variants", kMaxRuns),
                      "vary fewer values");
  std::set<std::string> folders;
  for (const std::vector<size_t>& combo : cartesianProduct(varies)) {
    BatchRun r{scene, "", sets, {}};
    for (size_t k = 0; k < varies.size(); ++k) {
      const Vary& v = varies[k];
      r.overrides.push_back(v.key + "=" + v.values[combo[k]]);
      r.labels.push_back(v.labels[combo[k]]);
      r.folder += (k ? "," : "") + v.key + "=" + folderPart(v.labels[combo[k]]);
    }
    if (!folders.insert(r.folder).second)
      throw UserError({"--vary", 0, 0}, "", "two variants would share the folder " + r.folder,
                      "give each key distinct values");
    p.runs.push_back(std::move(r));
  }
  identify(&p);
  return p;
}

std::pair<int, int> parseShard(const std::string& text) {
  const size_t slash = text.find('/');
  // digits only (no sign, no blanks) on both sides
  auto whole = [](const std::string& t) {
    return !t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; }) ? parseWhole(t)
                                                                                                      : std::nullopt;
  };
  const auto i = slash == std::string::npos ? std::nullopt : whole(text.substr(0, slash));
  const auto n = slash == std::string::npos ? std::nullopt : whole(text.substr(slash + 1));
  if (!i || !n || *n < 1 || *n > 1000000 || *i < 0 || *i >= *n)
    throw UserError({"--shard", 0, 0}, "", "expected I/N with whole numbers 0 <= I < N, got '" + text + "'",
                    "e.g. --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT");
  return {int(*i), int(*n)};
}

}  // namespace morphoflow
