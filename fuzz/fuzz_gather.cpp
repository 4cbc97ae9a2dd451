// libFuzzer target for `morphoflow gather`: the shard summaries of a batch
// folder (their schema, the shards' names and counts, the runs against the
// plan, every path a summary names) and the files they point at (last
// frames, read into a sweep's contact sheet). An input is the folder's files,
// each a line "=== PATH" (relative; letters, digits, '.', '-', '_' and '/')
// followed by its bytes.
#include <cstdint>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "batch/batch.h"
#include "batch/batch_summary.h"
#include "fuzz/fuzz_support.h"
#include "render/image_io.h"

using namespace morphoflow;
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kFileMark = "=== ";

bool safeName(const std::string& name) {
  if (name.empty() || name.size() > 200 || name.front() == '/') return false;
  for (const char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_' || c == '/')) return false;
  for (const fs::path& part : fs::path(name))
    if (part == ".." || part == ".") return false;
  return true;
}

// The input's files written under `dir` (at most 16; unsafe names skipped).
void writeFiles(std::string_view input, const fs::path& dir) {
  size_t at = input.rfind(kFileMark, 0) == 0 ? 0 : input.find("\n" + std::string(kFileMark));
  for (int files = 0; at != std::string_view::npos && files < 16; ++files) {
    const size_t nameStart = at + (input[at] == '\n' ? 1 : 0) + kFileMark.size();
    const size_t nameEnd = std::min(input.find('\n', nameStart), input.size());
    const size_t next = input.find("\n" + std::string(kFileMark), nameEnd);
    const std::string name(input.substr(nameStart, nameEnd - nameStart));
    const size_t body = std::min(nameEnd + 1, input.size());
    if (safeName(name))
      fuzz::writeBytes(dir / name, input.substr(body, (next == std::string_view::npos ? input.size() : next) - body));
    at = next;
  }
}

// A sweep of 5 runs over 2 shards and a batch of 3 over 3, each run with its
// last frame.
void writeSeeds(const fs::path& dir) {
  for (const auto& [kind, runs, shards] : {std::tuple{"sweep", 5, 2}, std::tuple{"batch", 3, 3}}) {
    BatchPlan plan;
    plan.kind = kind;
    plan.id = fmt::format("{}-{}", kind, runs);
    if (plan.kind == "sweep") plan.keys = {"rd.parameters.F"};
    std::vector<RunRecord> records;
    std::string input;
    const fs::path scratch = fuzz::freshScratch("gather-seed");
    for (int i = 0; i < runs; ++i) {
      RunRecord r;
      r.run = {"scenes/rd/gray_scott_pearson.toml", fmt::format("run-{}", i), {}, {}};
      if (!plan.keys.empty()) {
        r.run.overrides = {fmt::format("rd.parameters.F={}", 0.02 + 0.01 * i)};
        r.run.labels = {fmt::format("{}", 0.02 + 0.01 * i)};
      }
      r.status = "completed";
      r.exitCode = 0;
      r.steps = 100;
      r.frames = 2;
      r.bytesWritten = 1000;
      r.lastFrame = r.run.folder + "/frames/000001.png";
      std::string error;
      fs::create_directories((scratch / r.lastFrame).parent_path());
      writeRgb8((scratch / r.lastFrame).string(), 4, 4, std::vector<uint8_t>(48, uint8_t(40 * i)), &error);
      input += std::string(kFileMark) + r.lastFrame + "\n" + fuzz::readBytes(scratch / r.lastFrame) + "\n";
      plan.runs.push_back(r.run);
      records.push_back(r);
    }
    for (int s = 0; s < shards; ++s) {
      std::vector<RunRecord> mine;
      for (int i = s; i < runs; i += shards) mine.push_back(records[size_t(i)]);
      const std::string shard = fmt::format("{}/{}", s, shards);
      input += std::string(kFileMark) + summaryPath(".", shard).filename().string() + "\n" +
               summaryJson(plan, mine, shard).dump(1) + "\n";
    }
    fuzz::writeBytes(dir / kind, input);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(writeSeeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path dir = fuzz::freshScratch("gather");
  writeFiles(std::string_view(reinterpret_cast<const char*>(data), size), dir);
  std::ostringstream table;  // (the summary table gather prints)
  std::streambuf* const cout = std::cout.rdbuf(table.rdbuf());
  fuzz::expectUserErrorsOnly([&] { gatherBatch(dir.string()); });
  std::cout.rdbuf(cout);
  return 0;
}
