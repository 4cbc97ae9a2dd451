// Lid-driven cavity at Re = 100 on 128 x 128 against Ghia, Ghia & Shin
// (1982) Tables I and II: max |u - u_ref| <= 0.02 on the vertical centreline
// and max |v - v_ref| <= 0.02 on the horizontal one. Runs the shipped scene
// through the command line, as a user would.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"

using namespace morphoflow::testing;

TEST(CavityValidation, GhiaRe100At128) {
  auto out = tempDir("cavity");
  // Steady state is reached by t ~ 12 (the profile changes < 1e-4 after).
  CommandResult r = runMorphoflow("run " + sceneFile("lid_driven_cavity.toml") +
                                  " --set time.duration=15.0 --set output.images=false --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (auto [sim, ref] : {std::pair{"u_vertical_centerline", "ghia_re100_u_vertical_centerline"},
                          std::pair{"v_horizontal_centerline", "ghia_re100_v_horizontal_centerline"}}) {
    auto simRows = readCsv2(out / "profiles" / (std::string(sim) + ".csv"));
    auto refRows = readCsv2(std::filesystem::path(MORPHOFLOW_TEST_DATA) / (std::string(ref) + ".csv"));
    ASSERT_EQ(simRows.size(), 130u);  // 128 cell centres + both walls
    ASSERT_EQ(refRows.size(), 17u);
    double worst = 0;
    for (auto [coord, value] : refRows) {
      double err = std::abs(interpolate(simRows, coord) - value);
      worst = std::max(worst, err);
      EXPECT_LE(err, 0.02) << sim << " at " << coord;
    }
    RecordProperty(std::string(sim) + "_max_error", std::to_string(worst));
  }
  std::filesystem::remove_all(out);
}
