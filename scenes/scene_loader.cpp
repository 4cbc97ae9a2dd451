#include "scenes/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "scenes/scene_reader.h"

namespace morphoflow {

int editDistance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = int(i);
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

long Scene::totalSteps() const {
  if (time.steps > 0) return time.steps;
  return long(std::ceil(time.duration / time.dt - 1e-9));
}

namespace {

// A fixed step's semi-Lagrangian back-trace crosses speed x dt / h cells;
// beyond a million, cell positions lose their precision (and overflow an
// int further on). An adaptive step (time.cfl) bounds it itself.
void checkBackTraces(SceneContext& c, const Scene& s) {
  if (!s.hasFluid || s.time.cfl > 0) return;
  const double cells = s.probes.referenceSpeed * s.time.dt / (c.size[0] / c.res[0]);
  if (cells > 1e6) {
    const toml::table* time = c.root["time"].as_table();
    c.r.fail(
        time ? time->get("dt") : nullptr, "time.dt",
        fmt::format("a back-trace at speed {:g} crosses {:.3g} cells per step (speed x dt / cell size), more than 1e6",
                    s.probes.referenceSpeed, cells),
        "use a smaller time.dt, or set time.cfl");
  }
}

}  // namespace

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  return parseScene(readSceneText(path), path, overrides);
}

std::string readSceneText(const std::string& path) {
  // What the path is, before opening it: a FIFO would block and /dev/zero never ends.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status))
    throw UserError({path, 0, 0}, "", "cannot open the scene file", "check the path");
  if (!std::filesystem::is_regular_file(status))
    throw UserError({path, 0, 0}, "", "the scene is not a regular file (a folder, device or pipe)",
                    "give a .toml file");
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxSceneBytes)
    throw UserError({path, 0, 0}, "", "the scene file is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB",
                    "a scene is a short text file; give large data as images or expressions");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError({path, 0, 0}, "", "cannot open the scene file", "check the path and its permissions");
  std::string text(size_t(size), '\0');
  in.read(text.data(), std::streamsize(size));
  text.resize(size_t(in.gcount()));
  return text;
}

namespace {

// The sections of a tree (overrides applied, keyframes replaced by a value).
Scene parseTree(toml::table& root, const std::string& path, const std::map<std::string, SourceLocation>& overrideLocs) {
  Reader r(path, root, overrideLocs);
  Scene s;
  s.path = path;
  s.name = std::filesystem::path(path).stem().string();
  const std::filesystem::path sceneDir = std::filesystem::path(path).parent_path();
  const toml::table* top = &root;
  s.name = r.string(top, "", "name", s.name);
  s.seed = uint64_t(r.integer(top, "", "seed", 1, 0, (1L << 62)));

  SceneContext c{r, root, sceneDir, overrideLocs};
  parseGrid(c, &s);
  parseTime(c, &s);
  parseBoundary(c, &s);
  parseObstacles(c, &s);
  parseFluid(c, &s);
  parseRD(c, &s);
  parseVelocity(c, &s);
  parseSmoke(c, &s);
  parseCoupling(c, &s);
  parseOutput(c, &s);
  parseDeposits(c, &s);
  const bool singleOnGpu =
      r.string(r.table(root, "", "gpu"), "gpu.", "precision", "float", {"float", "double"}) == "float";
  s.gpuPrecision = singleOnGpu ? GpuPrecision::Float : GpuPrecision::Double;
  checkBackTraces(c, s);
  checkUntilSteady(c, s);
  s.inputs = r.inputs();
  s.numericKeys = r.numericKeys();
  s.givenKeys = r.givenKeys();
  for (const RDStroke& st : s.rd.strokes) s.timeline.strokeStarts.push_back(st.start);

  r.checkUnknown(root, "");
  return s;
}

// Every keyframe's value goes through the checks a value in the file does:
// the scene is read with it in place, an error named at the key's value.
void checkKeyframeValues(const toml::table& root, const std::string& path,
                         const std::map<std::string, SourceLocation>& overrideLocs,
                         const std::vector<KeyedValue>& keyed) {
  for (const KeyedValue& k : keyed)
    for (size_t i = 1; i < k.times.size(); ++i) {
      toml::table copy = root;
      std::map<std::string, SourceLocation> ignored;
      KeyedValue one = k;
      one.times = {0.0};
      one.values = {k.values[i]};
      applyOverride(copy, k.key + "=" + one.textAt(0.0), &ignored);
      try {
        parseTree(copy, path, overrideLocs);
      } catch (const UserError& e) {
        throw UserError(k.places[i], k.key, fmt::format("at t = {:g}: {}", k.times[i], e.message()), e.hint());
      }
    }
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& path, const std::vector<std::string>& overrides) {
  if (text.size() > kMaxSceneBytes)
    throw UserError({path, 0, 0}, "", "the scene is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB");
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw UserError({path, int(e.source().begin.line), int(e.source().begin.column)}, "",
                    "not valid TOML: " + std::string(e.description()));
  }
  std::map<std::string, SourceLocation> overrideLocs;
  for (const std::string& kv : overrides) applyOverride(root, kv, &overrideLocs);
  toml::table resolved = root;  // keyframes and all, for run.json and the settings hash

  Reader keys(path, root, overrideLocs);
  std::vector<KeyedValue> keyed = extractKeyframes(keys, root);
  checkKeyframeValues(root, path, overrideLocs, keyed);
  Scene s = parseTree(root, path, overrideLocs);
  s.timeline.keyed = std::move(keyed);
  if (!s.timeline.empty()) {
    s.timeline.text = text;
    s.timeline.overrides = overrides;
  }

  // The files it reads, by size and modification time: a changed input
  // changes the settings hash (a batch --resume runs the scene again).
  if (!s.inputs.empty()) {
    toml::table stamps;
    for (const SceneInput& in : s.inputs) {
      std::error_code ec;
      const auto size = std::filesystem::file_size(in.path, ec);
      const auto time = std::filesystem::last_write_time(in.path, ec).time_since_epoch().count();
      stamps.insert_or_assign(in.path, fmt::format("{} bytes, modified {}", ec ? 0 : size, ec ? 0 : time));
    }
    resolved.insert_or_assign("inputs", std::move(stamps));
  }
  // The scene as resolved, for run.json.
  std::ostringstream json;
  json << toml::json_formatter{resolved};
  s.resolvedJson = json.str();
  return s;
}

Scene sceneAt(const Scene& scene, double t) {
  const SceneTimeline& tl = scene.timeline;
  if (tl.empty()) return scene;
  Scene s = parseScene(tl.text, scene.path, tl.overridesAt(t));
  std::vector<ObstacleSpec> obstacles;
  for (size_t q = 0; q < s.fluid.obstacles.size(); ++q)
    if (tl.obstacles[q].contains(t)) obstacles.push_back(s.fluid.obstacles[q]);
  s.fluid.obstacles = std::move(obstacles);
  std::vector<RDStroke> strokes;
  for (const RDStroke& st : s.rd.strokes)
    if (st.start <= t) strokes.push_back(st);
  s.rd.strokes = std::move(strokes);
  s.timeline = SceneTimeline();
  s.resolvedJson = scene.resolvedJson;
  return s;
}

}  // namespace morphoflow
