// libFuzzer target for smoke scenes run to their end: sources (shapes,
// windows, motion, images and sdfs that find no file), temperature,
// buoyancy, weight, vorticity confinement, obstacles, the smoke mask of a
// coupled plume, and the outputs they write (PNG, sparse and half VDB).
// An input is a flags byte (bit 0: the 3D plume, else the 2D patterned one)
// and one --set override per line. The grid, the time and the image size are
// then set small, so that each input runs five steps. Besides the fuzzer's
// usual findings, a run that ends with exit 0 must leave finite fields, and
// no velocity it wrote into a volume may be inf or NaN.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "render/vdb_volume.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"

using namespace morphoflow;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> overridesOf(std::string_view text, bool three) {
  std::vector<std::string> out = fuzz::nonEmptyLines(text);
  // Last, so that they win: five steps on a small grid.
  for (const char* s : {"time={dt=0.01, duration=0.05}", "output.video=false", "output.image_size=64", "output.every=2",
                        "output.checkpoint_every=0"})
    out.emplace_back(s);
  out.emplace_back(three ? "grid={resolution=[12,20,12]}" : "grid={resolution=[12,18]}");
  if (!three) out.emplace_back("rd.resolution=[12,18]");
  return out;
}

template <int D>
void runToTheEnd(const std::vector<std::string>& overrides) {
  static const std::string dir = MORPHOFLOW_SCENE_DIR;
  const Scene scene =
      loadScene(dir + (D == 3 ? "/vfx/plume_obstacle_3d.toml" : "/vfx/plume_gray_scott_2d.toml"), overrides);
  if (scene.dimension != D) return;  // (grid.resolution gives the dimension: a 2D override on the 3D plume)
  const fs::path out = fuzz::freshScratch("smoke");
  RunOptions opt;
  opt.out = out.string();
  opt.quiet = true;
  auto sim = makeSimulation<D>(scene, Backend::TBB, [](const std::string&) {}, [](const std::string&) {});
  RunLog log(true, false);
  if (driveRun<D>(*sim, scene, opt, &log) != 0) return;
  try {
    sim->checkFinite("after a run that ended with exit 0");
  } catch (const NonFiniteError& e) {
    fuzz::finding(e.what());
  }
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() != ".vdb") continue;
    VelocityVolume v;
    std::string error;
    if (!readVdbVelocity(e.path().string(), &v, &error)) continue;  // (no velocity grid written)
    for (const std::vector<float>& c : v.values)
      for (const float x : c)
        if (!std::isfinite(x)) fuzz::finding(e.path().filename().string() + " holds a velocity of " + std::to_string(x));
  }
}

void writeSeeds(const fs::path& dir) {
  // (the flags byte, then the overrides)
  const std::vector<std::pair<char, std::string>> seeds = {
      {0, ""},
      {1, ""},
      {1, "output.vdb_half=true\nsources.0.temperature=1e6\noutput.vdb_fields=[\"dye\",\"temperature\"]"},
      {1, "smoke.vorticity=1e6"},
      {0, "smoke.buoyancy=1e9\nsmoke.weight=-1e9"},
      {0, "sources.0.motion=[\"0.5+0.3*sin(6*t)\",\"0.2\"]\nsources.0.start=0.02"},
      {1, "obstacles.0.boundary=\"voxel\"\nobstacles.0.size=[0.01,0.01,0.01]"},
      {0, "output.vdb=true\noutput.vdb_sparse=true\noutput.vdb_half=true\noutput.range=[0,0.5]"},
  };
  int i = 0;
  for (const auto& [flags, text] : seeds) fuzz::writeBytes(dir / ("seed-" + std::to_string(i++)), flags + text);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::writeSeedsIfAsked(writeSeeds);
  fuzz::runOnOneThread();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const bool three = data[0] & 1;
  const std::vector<std::string> overrides =
      overridesOf(std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1), three);
  fuzz::expectUserErrorsOnly([&] {
    if (three) runToTheEnd<3>(overrides);
    else runToTheEnd<2>(overrides);
  });
  return 0;
}
