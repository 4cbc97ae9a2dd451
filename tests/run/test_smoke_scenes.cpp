// Smoke scenes from the command line: [smoke] and [[sources]] are checked
// where they are read (exit 2, file:line:column), the GPU backend refuses
// them naming the stage, and a run writes the temperature beside the smoke.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>

#include "render/field_dump.h"
#include "render/image_io.h"
#include "render/legibility.h"

#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

const char* const kPlume = R"(name = "plume"
[grid]
resolution = [24, 32]
[domain]
size = [0.75, 1.0]
[time]
dt = 0.01
steps = 6
[boundary]
y_max = "outflow"
[fluid]
viscosity = 0.0
[smoke]
buoyancy = 1.0
vorticity = 1.0
cooling = 0.5
)";

const char* const kSource = R"(
[[sources]]
shape = "circle"
center = [0.375, 0.2]
radius = 0.08
density = 2.0
temperature = 4.0
)";

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p;
}

// Where `needle` starts in `text`: "line:column" (1-based).
std::string where(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  const size_t line = size_t(std::count(text.begin(), text.begin() + long(at), '\n')) + 1;
  const size_t col = at - (text.rfind('\n', at) == std::string::npos ? 0 : text.rfind('\n', at) + 1) + 1;
  return std::to_string(line) + ":" + std::to_string(col);
}

}  // namespace

TEST(SmokeScenes, BadSourcesAndSmokeWithoutAFluidAreLocatedErrors) {
  const fs::path dir = tempDir("smoke_errors");
  struct Case {
    std::string change, with, key, what;
  };
  const std::vector<Case> cases = {
      {"center = [0.375, 0.2]", "center = [0.375, 1.4]", "sources.0.center", "outside the domain"},
      {"density = 2.0", "density = -2.0", "sources.0.density", "expected a number in [0"},
      {"radius = 0.08", "radius = 0.08\nstart = 1.0\nend = 0.5", "sources.0.end", "before it starts"},
      {"density = 2.0\ntemperature = 4.0", "", "sources.0", "emits nothing"},
      {"radius = 0.08", "radius = 0.08\nmotion = [\"0.3 + * t\", \"0.2\"]", "sources.0.motion.0",
       "in the motion expression"},
  };
  for (const Case& c : cases) {
    std::string source = kSource;
    source.replace(source.find(c.change), c.change.size(), c.with);
    const std::string text = std::string(kPlume) + source;
    const fs::path scene = write(dir / "bad.toml", text);
    const CommandResult r = runMorphoflow("validate " + scene.string());
    EXPECT_EQ(r.status, 2) << c.key << "\n" << r.output;
    EXPECT_NE(r.output.find(c.key), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.what), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(scene.string() + ":"), std::string::npos) << r.output;
  }
  // Chemicals from a source need a layer; a smoke mask needs smoke.
  {
    const fs::path scene = write(dir / "chem.toml", std::string(kPlume) + kSource + "chemicals = [1.0]\n");
    const CommandResult r = runMorphoflow("validate " + scene.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("sources.0.chemicals"), std::string::npos) << r.output;
    const std::string cavity = sceneFile("coupled/cavity_gray_scott.toml");
    const CommandResult m =
        runMorphoflow("run " + cavity + " --set coupling.smoke_mask=0.1 --quiet --out " + (dir / "o").string());
    EXPECT_EQ(m.status, 2) << m.output;
    EXPECT_NE(m.output.find("no smoke to mask"), std::string::npos) << m.output;
  }
  // The density as an expression of fields: an unknown name is located.
  {
    const std::string text = std::string(kPlume) + kSource + "[output]\nvdb = true\nvdb_density = \"dye * nope\"\n";
    const fs::path scene = write(dir / "density.toml", text);
    const CommandResult r = runMorphoflow("validate " + scene.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("output.vdb_density"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("neither a field nor an expression"), std::string::npos) << r.output;
  }
  // A scene whose layer is carried by a given velocity has no fluid for smoke.
  const std::string given =
      "[grid]\nresolution = [16, 16]\n[time]\ndt = 0.01\nsteps = 2\n[rd]\nmodel = \"gray-scott\"\n"
      "[velocity]\nfield = [\"0\", \"0\"]\n[smoke]\nbuoyancy = 1.0\n";
  const fs::path scene = write(dir / "given.toml", given);
  const CommandResult r = runMorphoflow("validate " + scene.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(scene.string() + ":" + where(given, "[smoke]")), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("smoke needs a fluid"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// A source that opens after a short run has ended (a preview of a longer
// shot) runs, and the run says that it emitted nothing.
TEST(SmokeScenes, ASourceThatOpensAfterTheRunIsAWarning) {
  const fs::path dir = tempDir("smoke_late");
  std::string source = kSource;
  source.replace(source.find("radius = 0.08"), 13, "radius = 0.08\nstart = 0.5");
  const fs::path scene = write(dir / "late.toml", std::string(kPlume) + source);
  CommandResult r = runMorphoflow("run " + scene.string() + " --quiet --out " + (dir / "o").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("warning: sources.0 starts emitting at t = 0.5, when this run has ended (t = 0.06)"),
            std::string::npos) << r.output;
  r = runMorphoflow("run " + scene.string() + " --set sources.0.start=0.05 --quiet --out " + (dir / "o").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The GPU runs smoke and the pattern on it (their parity:
// GpuFluid.SmokeMatchesTheCpu, Gpu.PatternedPlumesMatchTheCpu).
TEST(SmokeScenes, TheGpuBackendRunsSmokeAndThePatternOnIt) {
  const fs::path dir = tempDir("smoke_gpu");
  const fs::path scene = write(dir / "plume.toml", std::string(kPlume) + kSource);
  CommandResult r = runMorphoflow("run " + scene.string() + " --backend gpu --quiet --out " + (dir / "o").string());
  if (r.output.find("no usable GPU context") != std::string::npos) GTEST_SKIP() << r.output;
  EXPECT_EQ(r.status, 0) << r.output;
  r = runMorphoflow("run " + sceneFile("vfx/plume_gray_scott_2d.toml") +
                    " --set grid.resolution=[16,24] --set rd.resolution=[32,48]" +
                    " --set time.duration=0.05 --backend gpu --quiet --out " + (dir / "p").string());
  EXPECT_EQ(r.status, 0) << r.output;
  fs::remove_all(dir);
}

// Through the scene file: the smoke the source emitted over the run (none
// has reached a side yet) is rate x time x area in the field dump, and the
// temperature beside it has cooled by exp(-cooling t) at most.
TEST(SmokeScenes, ARunDumpsTheSmokeItsSourceEmittedAndItsTemperature) {
  const fs::path dir = tempDir("smoke_run");
  const fs::path scene = write(dir / "plume.toml", std::string(kPlume) + kSource);
  const CommandResult r = runMorphoflow(
      "run " + scene.string() + " --quiet --set output.fields=true --set output.every=3 --out " + (dir / "o").string());
  ASSERT_EQ(r.status, 0) << r.output;
  morphoflow::FieldDump d;
  std::string err;
  ASSERT_TRUE(morphoflow::readFieldDump((dir / "o" / "fields" / "000002.exr").string(), &d, &err)) << err;
  auto channel = [&](const std::string& name) -> const std::vector<float>& {
    const size_t i = size_t(std::find(d.names.begin(), d.names.end(), name) - d.names.begin());
    EXPECT_LT(i, d.names.size()) << name;
    return d.channels.at(i);
  };
  const double cell = 0.75 / 24, area = M_PI * 0.08 * 0.08, t = 6 * 0.01;
  double smoke = 0, heat = 0;
  for (float v : channel("dye")) smoke += v * cell * cell;
  for (float v : channel("temperature")) heat += v * cell * cell;
  EXPECT_NEAR(smoke, 2.0 * t * area, 0.02 * 2.0 * t * area);
  EXPECT_LT(heat, 4.0 * t * area * 1.02);
  EXPECT_GT(heat, 4.0 * t * area * std::exp(-0.5 * t) * 0.98);
  fs::remove_all(dir);
}

// The shipped 3D patterned plume at half its size reads as a patterned
// element in the lit preview (docs/vfx.md, "Legibility"): its last frame's
// plume has a median luminance of at least 0.25 and a band-passed contrast
// of at least 0.12, and twice that of the same scene with the reaction off.
TEST(SmokeScenes, ThePatternedPlumeReadsInThePreview) {
  const fs::path dir = tempDir("plume_legibility");
  std::map<std::string, morphoflow::Legibility> m;
  for (const char* mode : {"ard", "passive"}) {
    const CommandResult r =
        runMorphoflow("run " + sceneFile("vfx/plume_gray_scott_3d.toml") +
                      " --set grid.resolution=[48,80,48] --set rd.resolution=[96,160,96] --set output.vdb=false"
                      " --set output.every=280 --set coupling.mode='\"" +
                      mode + "\"' --quiet --out " + (dir / mode).string());
    ASSERT_EQ(r.status, 0) << r.output;
    int w = 0, h = 0;
    std::vector<uint8_t> rgb;
    std::string err;
    ASSERT_TRUE(morphoflow::readRgb8((dir / mode / "frames" / "000001.png").string(), &w, &h, &rgb, &err)) << err;
    m[mode] = morphoflow::measureLegibility(rgb, w, h);
    std::cout << mode << ": median luminance " << m[mode].medianLuminance << ", band contrast " << m[mode].bandContrast
              << ", plume " << m[mode].plumeFraction << " of the frame\n";
  }
  EXPECT_GE(m["ard"].medianLuminance, 0.25);
  EXPECT_GE(m["ard"].bandContrast, 0.12);
  EXPECT_GE(m["ard"].bandContrast, 2.0 * m["passive"].bandContrast);
  fs::remove_all(dir);
}
