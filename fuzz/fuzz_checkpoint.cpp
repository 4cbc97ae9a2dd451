// libFuzzer target for checkpoints as `run --resume` reads them: the file's
// framing (magic, lengths, xxHash64), its JSON header (keys and types, the
// scene it names, the outputs' states, the log, another version's header)
// and the state's sections, loaded into a small scene of each kind. An input
// is a flags byte (bits 0-1: the scene; bit 2: the rest is the whole file;
// bit 3: --force), then either the file, or the header's text, a line
// "--state" and the state's bytes, framed and checksummed here so that the
// fuzzer reaches past the checksum.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <xxhash.h>

#include "fuzz/fuzz_support.h"
#include "run/checkpoint.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"

using namespace morphoflow;
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kStateMark = "\n--state\n";
constexpr long kResumeStep = 6;  // of 8: the seeds' older checkpoint, with steps left to run

// One small scene of each kind: reaction-diffusion, fluid, coupled, given velocity.
const Scene& sceneOf(int which) {
  static const std::vector<Scene> scenes = [] {
    const std::string dir = MORPHOFLOW_SCENE_DIR;
    const std::vector<std::string> common = {"output.every=2", "output.checkpoint_every=1",
                                             "output.video=false"};
    auto with = [&](std::vector<std::string> more) {
      more.insert(more.begin(), common.begin(), common.end());
      return more;
    };
    return std::vector<Scene>{
        loadScene(dir + "/rd/gray_scott_pearson.toml", with({"grid.resolution=[16,16]", "time.steps=8"})),
        loadScene(dir + "/lid_driven_cavity.toml",
                  with({"grid.resolution=[16,16]", "time.duration=0.08", "time.cfl=0", "probes.centerlines=false"})),
        loadScene(dir + "/coupled/cavity_gray_scott.toml",
                  with({"grid.resolution=[16,16]", "rd.resolution=[16,16]", "time.steps=8"})),
        loadScene(dir + "/flow/cavity_vdb_gray_scott.toml", with({"grid.resolution=[16,16]", "time.steps=8"})),
    };
  }();
  return scenes.at(size_t(which));
}

int resumeFrom(int which, bool force, const fs::path& out) {
  const Scene& scene = sceneOf(which);
  auto sim = makeSimulation<2>(scene, Backend::TBB, [](const std::string&) {}, [](const std::string&) {});
  RunOptions opt;
  opt.out = out.string();
  opt.quiet = true;
  opt.resume = true;
  opt.force = force;
  RunLog log(true, false);
  return driveRun<2>(*sim, scene, opt, &log);
}

std::string frame(std::string_view header, std::string_view state) {
  std::string file = "MFCKPT01";
  auto put64 = [&](uint64_t v) { file.append(reinterpret_cast<const char*>(&v), 8); };
  put64(header.size());
  file += header;
  put64(state.size());
  file += state;
  put64(XXH64(file.data(), file.size(), 0));
  return file;
}

// Each scene run to its end with a checkpoint every frame; the one at step 6,
// both framed and whole.
void writeSeeds(const fs::path& dir) {
  for (int which = 0; which < 4; ++which) {
    const fs::path out = fuzz::freshScratch("checkpoint-seed");
    RunOptions opt;
    opt.out = out.string();
    opt.quiet = true;
    const Scene& scene = sceneOf(which);
    auto sim = makeSimulation<2>(scene, Backend::TBB, [](const std::string&) {}, [](const std::string&) {});
    RunLog log(true, false);
    driveRun<2>(*sim, scene, opt, &log);
    const Checkpoint c = readCheckpoint(checkpointFile(out, kResumeStep));
    fuzz::writeBytes(dir / ("framed-" + std::to_string(which)), std::string(1, char(which)) + c.header.toJson().dump() +
                                                                     std::string(kStateMark) + c.state);
    fuzz::writeBytes(dir / ("whole-" + std::to_string(which)),
                     std::string(1, char(which | 4)) + fuzz::readBytes(checkpointFile(out, kResumeStep)));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(writeSeeds);
  fuzz::runOnOneThread();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int flags = data[0];
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::string file;
  if (flags & 4) {
    file = rest;
  } else {
    const size_t at = rest.find(kStateMark);
    file =
        at == std::string_view::npos ? frame(rest, {}) : frame(rest.substr(0, at), rest.substr(at + kStateMark.size()));
  }
  const fs::path out = fuzz::freshScratch("checkpoint");
  fuzz::writeBytes(checkpointFile(out, kResumeStep), file);
  fuzz::expectUserErrorsOnly([&] { resumeFrom(flags & 3, flags & 8, out); });
  return 0;
}
