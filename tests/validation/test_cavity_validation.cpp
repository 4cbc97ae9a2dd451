// Lid-driven cavity against Ghia, Ghia & Shin (1982) Tables I and II: the
// shipped scene, run until steady (its time.until_steady) as a user would,
// at Re = 100, 400 and 1000 at the resolutions the scene file states (128^2,
// 256^2, 384^2); max |u - u_ref| on the vertical centreline and max
// |v - v_ref| on the horizontal one within 0.01. Re = 1000 (5 minutes on 2
// cores) runs with MORPHOFLOW_FULL_VALIDATION=1.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"
#include "tests/validation/run_in_process.h"

using namespace morphoflow::testing;

namespace {

void expectGhia(int reynolds, int n) {
  auto out = tempDir("cavity_" + std::to_string(reynolds));
  const std::string grid = "grid.resolution=[" + std::to_string(n) + "," + std::to_string(n) + "]";
  ASSERT_EQ(runInProcess(sceneFile("lid_driven_cavity.toml"),
                         {"fluid.reynolds=" + std::to_string(reynolds), grid, "output.images=false"}, out),
            0);
  std::ifstream in(out / "run.json");
  const nlohmann::json run = nlohmann::json::parse(in);
  EXPECT_TRUE(run["until_steady"]["steady"].get<bool>()) << run["until_steady"].dump();
  ::testing::Test::RecordProperty("steady_at_time", std::to_string(run["time"].get<double>()));
  for (auto [sim, ref] : {std::pair{"u_vertical_centerline", "u_vertical_centerline"},
                          std::pair{"v_horizontal_centerline", "v_horizontal_centerline"}}) {
    auto simRows = readCsv2(out / "profiles" / (std::string(sim) + ".csv"));
    auto refRows = readCsv2(std::filesystem::path(MORPHOFLOW_TEST_DATA) /
                            ("ghia_re" + std::to_string(reynolds) + "_" + ref + ".csv"));
    ASSERT_EQ(simRows.size(), size_t(n + 2));  // n cell centres + both walls
    ASSERT_GE(refRows.size(), 16u);
    double worst = 0;
    for (auto [coord, value] : refRows) {
      double err = std::abs(interpolate(simRows, coord) - value);
      worst = std::max(worst, err);
      EXPECT_LE(err, 0.01) << "Re " << reynolds << " " << sim << " at " << coord;
    }
    ::testing::Test::RecordProperty(std::string(sim) + "_max_error", std::to_string(worst));
  }
  std::filesystem::remove_all(out);
}

}  // namespace

TEST(CavityValidation, GhiaRe100At128) { expectGhia(100, 128); }
TEST(CavityValidation, GhiaRe400At256) { expectGhia(400, 256); }
TEST(CavityValidation, GhiaRe1000At384) {
  if (!fullValidation()) GTEST_SKIP() << "5 minutes on 2 cores: set MORPHOFLOW_FULL_VALIDATION=1";
  expectGhia(1000, 384);
}
