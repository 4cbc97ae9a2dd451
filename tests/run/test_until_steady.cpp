// time.until_steady through the command line: a run ends at the first frame
// whose velocity changes by less than the tolerance per unit time, and has
// then stopped changing (running on moves the profiles by no more than the
// tolerance allows); a cap ends a run that never gets there, saying so; a
// scene without a fluid is refused at the key.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

using namespace morphoflow::testing;
namespace fs = std::filesystem;

namespace {

nlohmann::json runJson(const fs::path& out) { return nlohmann::json::parse(std::ifstream(out / "run.json")); }

const std::string kCavity = " --set grid.resolution=[32,32] --set output.images=false --quiet";

}  // namespace

TEST(UntilSteady, ARunStopsAtSteadyStateAndHasStoppedChanging) {
  const fs::path dir = tempDir("until_steady");
  const double tol = 1e-3;
  CommandResult r =
      runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") + kCavity +
                    " --set time.until_steady=1e-3 --set time.duration=100 --out " + (dir / "a").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json a = runJson(dir / "a");
  const nlohmann::json& s = a["until_steady"];
  ASSERT_TRUE(s["steady"].get<bool>()) << s.dump();
  EXPECT_EQ(s["stopped_because"], "steady");
  EXPECT_LT(s["relative_change_per_time"].get<double>(), tol);
  const double t = a["time"].get<double>();
  EXPECT_GT(t, 1.0);
  EXPECT_LT(t, 50.0);
  EXPECT_EQ(s["steady_at"]["step"], a["steps"]);
  // The same scene run 5 time units further without the criterion: the
  // centreline profile moves by at most 5 x tol of the lid speed (x 2 for
  // the decay not being exactly exponential).
  r = runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") + kCavity +
                    " --set time.until_steady=0 --set time.duration=" + std::to_string(t + 5.0) + " --out " +
                    (dir / "b").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(runJson(dir / "b").contains("until_steady"));
  const auto pa = readCsv2(dir / "a" / "profiles" / "u_vertical_centerline.csv");
  const auto pb = readCsv2(dir / "b" / "profiles" / "u_vertical_centerline.csv");
  ASSERT_EQ(pa.size(), pb.size());
  double moved = 0;
  for (size_t i = 0; i < pa.size(); ++i) moved = std::max(moved, std::abs(pa[i].second - pb[i].second));
  EXPECT_LE(moved, 2 * 5 * tol) << "the flow was still changing";
  EXPECT_GT(moved, 0.0);
  fs::remove_all(dir);
}

TEST(UntilSteady, ACappedRunSaysItIsNotSteadyAndWhatStoppedIt) {
  const fs::path dir = tempDir("until_steady_cap");
  CommandResult r =
      runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") +
                    " --set grid.resolution=[32,32] --set output.images=false --set time.until_steady=1e-9"
                    " --set time.duration=2 --out " +
                    (dir / "o").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("warning: not steady by t = 2"), std::string::npos) << r.output;
  const nlohmann::json s = runJson(dir / "o")["until_steady"];
  EXPECT_FALSE(s["steady"].get<bool>());
  EXPECT_EQ(s["stopped_because"], "time.duration");
  EXPECT_GT(s["relative_change_per_time"].get<double>(), 1e-9);
  EXPECT_FALSE(s.contains("steady_at"));
  fs::remove_all(dir);
}

// No frame within the run, so no measurement: said as such (not "changes by
// inf"), with the output.every that would measure it, and why in run.json.
TEST(UntilSteady, ARunWithNoFrameToMeasureAtSaysSo) {
  const fs::path dir = tempDir("until_steady_unmeasured");
  CommandResult r =
      runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") +
                    " --set grid.resolution=[16,16] --set output.images=false --set time.until_steady=1e-3"
                    " --set time.duration=0.5 --set output.every=1000 --out " +
                    (dir / "o").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("steadiness not measured"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("give output.every <= 50"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("inf"), std::string::npos) << r.output;
  const nlohmann::json s = runJson(dir / "o")["until_steady"];
  EXPECT_TRUE(s["relative_change_per_time"].is_null());
  EXPECT_EQ(s["not_measured_because"], "output.every (1000 steps) is longer than the run (50 steps)");
  fs::remove_all(dir);
}

TEST(UntilSteady, IsRefusedWithoutAFluidAndOutOfRange) {
  const fs::path dir = tempDir("until_steady_bad");
  const std::string rd =
      "[grid]\nresolution = [16, 16]\n[time]\ndt = 0.5\nuntil_steady = 1e-4\n[rd]\nmodel = \"gray-scott\"\n";
  const fs::path scene = dir / "rd.toml";
  std::ofstream(scene) << rd;
  CommandResult r = runMorphoflow("validate " + scene.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(scene.string() + ":5:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("has no fluid"), std::string::npos) << r.output;
  r = runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") + " --set time.until_steady=-1 --out " +
                    (dir / "o").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("time.until_steady"), std::string::npos) << r.output;
  fs::remove_all(dir);
}
