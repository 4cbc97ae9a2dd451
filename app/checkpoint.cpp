#include "app/checkpoint.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <xxhash.h>

#include "core/error.h"
#include "core/output_file.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

constexpr char kMagic[8] = {'M', 'F', 'C', 'K', 'P', 'T', '0', '1'};

void append64(std::string* s, uint64_t v) { s->append(reinterpret_cast<const char*>(&v), 8); }

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

}  // namespace

fs::path checkpointDir(const fs::path& out) { return out / "checkpoints"; }

fs::path checkpointFile(const fs::path& out, long step) {
  return checkpointDir(out) / fmt::format("{:010d}.ckpt", step);
}

fs::path writeCheckpoint(const fs::path& out, long step, const nlohmann::json& header, StateWriter* state) {
  createOutputFolder(checkpointDir(out));
  const std::string h = header.dump();
  const size_t n = state->serialisedSize();
  std::string bytes;
  bytes.reserve(8 + 8 + h.size() + 8 + n + 8);  // one allocation: no copy of the state while it grows
  bytes.assign(kMagic, 8);
  append64(&bytes, h.size());
  bytes += h;
  append64(&bytes, n);
  state->serialiseInto(&bytes);
  append64(&bytes, XXH64(bytes.data(), bytes.size(), 0));
  const fs::path file = checkpointFile(out, step);
  writeFileAtomically(file, bytes);
  const std::vector<fs::path> all = checkpointsNewestFirst(checkpointDir(out));
  std::error_code ec;
  for (size_t i = 2; i < all.size(); ++i) fs::remove(all[i], ec);
  return file;
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
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string bytes = buf.str();
  if (bytes.size() < 8 + 8 + 8 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) throw bad("it is not a morphoflow checkpoint, or it is cut short");
  const size_t body = bytes.size() - 8;
  if (XXH64(bytes.data(), body, 0) != read64(bytes, body)) throw bad("its checksum does not match (cut short or corrupted)");
  const uint64_t hn = read64(bytes, 8);
  if (hn > body - 16) throw bad("its header is cut short");
  const uint64_t sn = read64(bytes, 16 + hn);
  if (16 + hn + 8 + sn != body) throw bad("its state is cut short");
  Checkpoint c;
  c.file = file;
  try {
    c.header = nlohmann::json::parse(bytes.substr(16, hn));
  } catch (const std::exception& e) {
    throw bad(std::string("its header is not JSON: ") + e.what());
  }
  c.state = bytes.substr(16 + hn + 8, sn);
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
