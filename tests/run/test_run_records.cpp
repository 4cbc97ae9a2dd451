// What a run says and records: progress piped to a file is plain lines (no
// carriage returns) and --quiet silences it; log.txt keeps the lines;
// run.json records how the run ended, its peak memory against the estimate
// made before allocating, and the bytes written per output kind; a scene
// too large for the machine is refused before anything is allocated.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

std::string text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

nlohmann::json runJson(const fs::path& out) { return nlohmann::json::parse(std::ifstream(out / "run.json")); }

}  // namespace

TEST(RunRecords, ProgressToAPipeIsPlainLinesAndQuietIsSilent) {
  const fs::path dir = tempDir("records_progress");
  const std::string args = "run " + sceneFile("coupled/cavity_gray_scott.toml") +
                           " --set grid.resolution=[24,24] --set rd.resolution=[24,24] --set time.steps=20"
                           " --set output.every=5 --set output.video=false --out ";
  CommandResult r = runMorphoflow(args + (dir / "loud").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find('\r'), std::string::npos);
  EXPECT_NE(r.output.find("done: 20 steps"), std::string::npos) << r.output;
  EXPECT_NE(text(dir / "loud" / "log.txt").find("done: 20 steps"), std::string::npos);
  CommandResult q = runMorphoflow(args + (dir / "quiet").string() + " --quiet");
  ASSERT_EQ(q.status, 0);
  EXPECT_EQ(q.output, "");
  EXPECT_NE(text(dir / "quiet" / "log.txt").find("done: 20 steps"), std::string::npos);
  fs::remove_all(dir);
}

TEST(RunRecords, OnATerminalProgressIsOneLineRedrawnInPlace) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1) to give the run a terminal";
  const fs::path dir = tempDir("records_tty");
  // script(1) runs the command on a pseudo-terminal and copies what it shows.
  const std::string cmd = "script -qec \"" + std::string(MORPHOFLOW_BINARY) + " run " +
                          sceneFile("coupled/cavity_gray_scott.toml") +
                          " --set grid.resolution=[64,64] --set rd.resolution=[96,96] --set time.steps=600"
                          " --set output.every=100 --set output.video=false --out " + (dir / "out").string() +
                          "\" " + (dir / "typescript").string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string shown = text(dir / "typescript");
  EXPECT_NE(shown.find('\r'), std::string::npos) << "the line is redrawn with carriage returns";
  for (const char* word : {"frame ", "step ", "t = ", "steps/s", "ETA "})
    EXPECT_NE(shown.find(word), std::string::npos) << word << " in: " << shown;
  fs::remove_all(dir);
}

TEST(RunRecords, RunJsonSaysHowItEndedAndWhatItWrote) {
  const fs::path dir = tempDir("records_json");
  CommandResult r =
      runMorphoflow("run " + sceneFile("coupled/cavity_gray_scott.toml") +
                    " --set grid.resolution=[24,24] --set rd.resolution=[24,24] --set time.steps=8"
                    " --set output.every=4 --set output.fields=true --set output.vdb=true --quiet --out " +
                    (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = runJson(dir / "out");
  EXPECT_EQ(j["exit_state"], "completed");
  EXPECT_EQ(j["settings_hash"].get<std::string>().size(), 16u);
  EXPECT_GT(j["peak_memory_bytes"].get<double>(), 1e6);
  // Bytes per kind: what is on disk.
  auto sum = [&](const fs::path& sub) {
    uintmax_t n = 0;
    for (const auto& e : fs::directory_iterator(dir / "out" / sub)) n += fs::file_size(e.path());
    return n;
  };
  EXPECT_EQ(j["bytes_written"]["frames"].get<uintmax_t>(), sum("frames"));
  EXPECT_EQ(j["bytes_written"]["fields"].get<uintmax_t>(), sum("fields"));
  EXPECT_EQ(j["bytes_written"]["vdb"].get<uintmax_t>(), sum("vdb"));
  EXPECT_GT(j["bytes_written"]["checkpoints"].get<uintmax_t>(), 0u);
  // A run that diverges records it, with the message (exit 2: the scene's dt is the cause).
  CommandResult bad = runMorphoflow("run " + sceneFile("rd/turing_lawlor.toml") +
                                    " --set grid.resolution=[32,32] --set 'rd.integrator=\"explicit\"' --set time.dt=50"
                                    " --set time.steps=40 --set output.every=10 --quiet --out " +
                                    (dir / "bad").string());
  EXPECT_EQ(bad.status, 2) << bad.output;
  const nlohmann::json f = runJson(dir / "bad");
  EXPECT_EQ(f["exit_state"], "diverged");
  EXPECT_NE(f["error"].get<std::string>().find("diverged"), std::string::npos) << f.dump();
  EXPECT_NE(text(dir / "bad" / "log.txt"), "");
  fs::remove_all(dir);
}

// A fixed output.range maps to 8-bit colours: the shown cells beyond it are
// drawn at its ends, counted in run.json and said in one line.
TEST(RunRecords, AFixedRangeSaysHowMuchOfTheFieldLayBeyondIt) {
  const fs::path dir = tempDir("records_range");
  for (const auto& [range, beyond] :
       {std::pair{std::string("[-1.0,1.0]"), true}, std::pair{std::string("[-1e9,1e9]"), false}}) {
    CommandResult r =
        runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") +
                      " --set grid.resolution=[32,32] --set time.duration=0.5 --set output.range=" + range + " --out " +
                      (dir / "o").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "o" / "run.json");
    const nlohmann::json f = nlohmann::json::parse(in)["frames_range"];
    EXPECT_EQ(f["cells_beyond"].get<long>() > 0, beyond) << f;
    EXPECT_EQ(r.output.find("lay beyond output.range") != std::string::npos, beyond) << r.output;
    if (beyond) {
      EXPECT_GT(f["fraction_beyond"].get<double>(), 0.01) << f;
    }
  }
  fs::remove_all(dir);
}

TEST(RunRecords, TheMemoryEstimateMatchesThePeakAndATooLargeRunIsRefused) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "under AddressSanitizer the peak includes its shadow memory and redzones (scripts/asan)";
#endif
  const fs::path dir = tempDir("records_memory");
  for (const std::string& sets :
       {std::string(" --set grid.resolution=[64,64,64] --set rd.resolution=[64,64,64] --set time.steps=4"),
        std::string(" --set grid.resolution=[48,48,48] --set rd.resolution=[96,96,96] --set time.steps=4")}) {
    CommandResult r =
        runMorphoflow("run " + sceneFile("coupled/cavity_gray_scott_3d.toml") + sets +
                      // a frame after each step, as a run writes them (an initial
                      // frame alone meets no solver's work vectors)
                      " --set output.every=1 --set output.video=false --set output.images=false --quiet --out " +
                      (dir / "out").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json j = runJson(dir / "out");
    const double peak = j["peak_memory_bytes"].get<double>(), estimate = j["memory_estimate_bytes"].get<double>();
    EXPECT_NEAR(estimate / peak, 1.0, 0.10) << sets << ": estimate " << estimate << ", peak " << peak;
  }
  CommandResult v = runMorphoflow("validate " + sceneFile("coupled/cavity_gray_scott_3d.toml"));
  EXPECT_NE(v.output.find("needs about"), std::string::npos) << v.output;
  CommandResult big = runMorphoflow("run " + sceneFile("coupled/cavity_gray_scott_3d.toml") +
                                    " --set grid.resolution=[640,640,640] --out " + (dir / "big").string());
  EXPECT_EQ(big.status, 2) << big.output;
  EXPECT_NE(big.output.find("GiB of memory"), std::string::npos) << big.output;
  EXPECT_NE(big.output.find("available"), std::string::npos) << big.output;
  EXPECT_FALSE(fs::exists(dir / "big" / "run.json"));
  fs::remove_all(dir);
}

// A run ends by naming what to open: a 3D run its VDB sequence and the line
// that loads it in Blender (whose file exists), a 2D run its animation and
// its newest frame.
TEST(RunRecords, ARunEndsByNamingWhatToOpenAndHow) {
  const fs::path dir = tempDir("where_to_look");
  const CommandResult vol =
      runMorphoflow("run " + sceneFile("lid_driven_cavity_3d.toml") +
                    " --set grid.resolution=[8,8,8] --set time.duration=0.05 --set output.vdb=true"
                    " --set output.video=false --out " +
                    (dir / "3d").string());
  ASSERT_EQ(vol.status, 0) << vol.output;
  const fs::path first = dir / "3d" / "vdb" / "lid_driven_cavity_3d.000000.vdb";
  ASSERT_TRUE(fs::exists(first));
  EXPECT_NE(vol.output.find("volumes: " + (dir / "3d" / "vdb" / "lid_driven_cavity_3d.######.vdb").string()),
            std::string::npos) << vol.output;
  EXPECT_NE(vol.output.find("bpy.ops.object.volume_import(filepath='" + first.string() + "')"), std::string::npos)
      << vol.output;
  const CommandResult flat =
      runMorphoflow("run " + sceneFile("rd/gray_scott_pearson.toml") +
                    " --set grid.resolution=[32,32] --set time.steps=20 --set output.every=10 --set output.video=true"
                    " --out " +
                    (dir / "2d").string());
  ASSERT_EQ(flat.status, 0) << flat.output;
  EXPECT_NE(flat.output.find("newest frame: " + (dir / "2d" / "frames" / "000002.png").string()), std::string::npos)
      << flat.output;
  ASSERT_TRUE(fs::exists(dir / "2d" / "gray_scott_pearson.mp4")) << "ffmpeg is one of scripts/setup's packages";
  EXPECT_NE(flat.output.find("animation: " + (dir / "2d" / "gray_scott_pearson.mp4").string()), std::string::npos)
      << flat.output;
  fs::remove_all(dir);
}
