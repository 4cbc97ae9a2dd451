#include "run/checkpoint.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <xxhash.h>

#include "core/error.h"
#include "core/output_file.h"
#include "run/memory_estimate.h"
#include "run/output_kinds.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

constexpr char kMagic[8] = {'M', 'F', 'C', 'K', 'P', 'T', '0', '1'};

uint64_t read64(const std::string& s, size_t at) {
  uint64_t v;
  std::memcpy(&v, s.data() + at, 8);
  return v;
}

std::vector<fs::path> checkpointsNewestFirst(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".ckpt") files.push_back(e.path());
  std::sort(files.rbegin(), files.rend());  // zero-padded step numbers sort by step
  return files;
}

// What the driver reads of a header: the keys it needs, of their types; a
// header without them is unusable as a damaged file is (an empty string: it has them).
std::string headerProblem(const nlohmann::json& h) {
  if (!h.is_object()) return "its header is not a JSON object";
  auto has = [&](const char* key, bool (nlohmann::json::*is)() const noexcept) {
    return h.contains(key) && (h[key].*is)();
  };
  for (const char* key : {"version", "scene_hash", "scene", "log"})
    if (!has(key, &nlohmann::json::is_string)) return std::string("its header lacks the text '") + key + "'";
  for (const char* key : {"step", "last_frame"})
    if (!has(key, &nlohmann::json::is_number_integer))
      return std::string("its header lacks the whole number '") + key + "'";
  if (h["step"].get<long>() < 0 || h["last_frame"].get<long>() < -1) return "its header holds a negative step or frame";
  if (!has("checkpoint_bytes", &nlohmann::json::is_number_unsigned))
    return "its header lacks the byte count 'checkpoint_bytes'";
  if (!has("time", &nlohmann::json::is_number)) return "its header lacks the number 'time'";
  if (!has("sinks", &nlohmann::json::is_array)) return "its header lacks the outputs' list 'sinks'";
  if (h.contains("python")) {
    const nlohmann::json& p = h["python"];
    if (!p.is_object() || !p.contains("scene_text") || !p["scene_text"].is_string() || !p.contains("scene_path") ||
        !p["scene_path"].is_string() || !p.contains("overrides") || !p["overrides"].is_array())
      return "its header's 'python' lacks the scene's text, path or overrides";
    for (const nlohmann::json& o : p["overrides"])
      if (!o.is_string()) return "its header's 'python' holds an override that is not text";
  }
  for (const nlohmann::json& sink : h["sinks"]) {
    if (!sink.is_object()) return "an output's state in its header is not an object";
    for (const char* key : {"written", "bytes"})
      if (!sink.contains(key)) return std::string("an output's state in its header lacks '") + key + "'";
    for (const auto& [key, value] : sink.items()) {
      if (!value.is_number_integer()) return "its header holds an output's '" + key + "' that is not a whole number";
      if (value.get<long long>() < -1) return "its header holds an output's '" + key + "' that is negative";
    }
  }
  return "";
}

}  // namespace

nlohmann::json CheckpointHeader::toJson() const {
  nlohmann::json h = {{"version", version}, {"scene_hash", sceneHash}, {"scene", scene},
                      {"step", step},       {"time", time},            {"last_frame", lastFrame},
                      {"sinks", sinks},     {"log", log},              {"checkpoint_bytes", checkpointBytes}};
  if (python)
    h["python"] = {{"scene_text", python->text}, {"scene_path", python->path}, {"overrides", python->overrides}};
  return h;
}

CheckpointHeader CheckpointHeader::fromJson(const nlohmann::json& h) {
  CheckpointHeader c;
  c.version = h.at("version").get<std::string>();
  c.sceneHash = h.at("scene_hash").get<std::string>();
  c.scene = h.at("scene").get<std::string>();
  c.step = h.at("step").get<long>();
  c.time = h.at("time").get<double>();
  c.lastFrame = h.at("last_frame").get<long>();
  c.sinks = h.at("sinks");
  c.log = h.at("log").get<std::string>();
  c.checkpointBytes = h.at("checkpoint_bytes").get<uintmax_t>();
  if (h.contains("python")) {
    const nlohmann::json& p = h["python"];
    c.python = PythonScene{p.at("scene_text").get<std::string>(), p.at("scene_path").get<std::string>(),
                           p.at("overrides").get<std::vector<std::string>>()};
  }
  return c;
}

fs::path checkpointDir(const fs::path& out) { return out / kCheckpointFiles.folder; }

fs::path checkpointFile(const fs::path& out, long step) {
  return checkpointDir(out) / fmt::format("{:010d}.ckpt", step);
}

fs::path writeCheckpoint(const fs::path& out, long step, const CheckpointHeader& header,
                         const std::function<void(StateWriter*)>& save) {
  createOutputFolder(checkpointDir(out));
  const fs::path file = checkpointFile(out, step);
  writeCheckpointFile(file, header, save);
  const std::vector<fs::path> all = checkpointsNewestFirst(checkpointDir(out));
  std::error_code ec;
  for (size_t i = 2; i < all.size(); ++i) fs::remove(all[i], ec);
  return file;
}

void writeCheckpointFile(const fs::path& file, const CheckpointHeader& header,
                         const std::function<void(StateWriter*)>& save) {
  const std::string h = header.toJson().dump();
  // The state's length comes first in the file: one pass counts it, the
  // next streams the sections straight from the solvers into the file.
  uint64_t n = 0;
  StateWriter counter([&](std::string_view frame, const void*, size_t bytes) { n += frame.size() + bytes; });
  save(&counter);
  AtomicFile f(file);
  std::unique_ptr<XXH64_state_t, decltype(&XXH64_freeState)> hash(XXH64_createState(), &XXH64_freeState);
  XXH64_reset(hash.get(), 0);
  auto put = [&](const void* data, size_t bytes) {
    f.write(data, bytes);
    XXH64_update(hash.get(), data, bytes);
  };
  auto put64 = [&](uint64_t v) { put(&v, 8); };
  put(kMagic, 8);
  put64(h.size());
  put(h.data(), h.size());
  put64(n);
  uint64_t written = 0;
  StateWriter streamer([&](std::string_view frame, const void* data, size_t bytes) {
    put(frame.data(), frame.size());
    put(data, bytes);
    written += frame.size() + bytes;
  });
  save(&streamer);
  if (written != n) throw std::logic_error("checkpoint: the state changed between its two passes");
  const uint64_t digest = XXH64_digest(hash.get());
  f.write(&digest, 8);
  f.commit();
}

Checkpoint readCheckpoint(const fs::path& file) {
  auto bad = [&](const std::string& why) {
    return UserError({file.string(), 0, 0}, "", "the checkpoint is unusable: " + why,
                     "an older checkpoint is used if one is intact; else run the scene again without --resume");
  };
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(file, ec))) throw bad("it is not a regular file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw bad("it cannot be opened");
  const uintmax_t size = fs::file_size(file, ec);
  if (ec) throw bad("it cannot be read");
  // (a file of a size no run writes, e.g. a sparse one, is never allocated)
  if (const uintmax_t free = availableBytes(); size > free)
    throw bad("it is " + humanBytes(size) + ", more than the " + humanBytes(free) + " of memory free");
  std::string bytes;
  try {
    bytes.assign(size_t(size), '\0');
  } catch (const std::bad_alloc&) {
    throw bad("it is " + humanBytes(size) + ", more than this process can hold");
  }
  if (!in.read(bytes.data(), std::streamsize(bytes.size()))) throw bad("it cannot be read");
  if (bytes.size() < 8 + 8 + 8 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw bad("it is not a morphoflow checkpoint, or it is cut short");
  const size_t body = bytes.size() - 8;
  if (XXH64(bytes.data(), body, 0) != read64(bytes, body))
    throw bad("its checksum does not match (cut short or corrupted)");
  const uint64_t hn = read64(bytes, 8);
  if (hn > body - 16) throw bad("its header is cut short");
  const uint64_t sn = read64(bytes, 16 + hn);
  if (16 + hn + 8 + sn != body) throw bad("its state is cut short");
  Checkpoint c;
  c.file = file;
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(bytes.substr(16, hn));
  } catch (const std::exception& e) {
    throw bad(std::string("its header is not JSON: ") + e.what());
  }
  if (const std::string problem = headerProblem(header); !problem.empty()) throw bad(problem);
  c.header = CheckpointHeader::fromJson(header);
  // The state stays in the bytes read (no copy of a large run's state).
  bytes.resize(body);
  bytes.erase(0, 16 + hn + 8);
  c.state = std::move(bytes);
  return c;
}

bool hasCheckpoint(const fs::path& out) { return !checkpointsNewestFirst(checkpointDir(out)).empty(); }

Checkpoint latestCheckpoint(const fs::path& out, const std::function<void(const std::string&)>& warn) {
  const std::vector<fs::path> files = checkpointsNewestFirst(checkpointDir(out));
  for (const fs::path& f : files) {
    try {
      return readCheckpoint(f);
    } catch (const UserError& e) {
      warn(std::string("warning: ") + e.what());
    }
  }
  throw UserError({checkpointDir(out).string(), 0, 0}, "--resume",
                  files.empty() ? "there is no checkpoint to resume from" : "no checkpoint here is intact",
                  "run the scene without --resume (with the same --out) to start it afresh");
}

}  // namespace morphoflow
