// Steady flow past a cylinder against Schaefer & Turek (1996), the DFG
// benchmarks, with the cylinder's boundary cut (fluid/cut_cells.h) and the
// forces integrated on its surface: 2D-1 (Re = 20, 880 x 164 cells: drag
// within 1% of 5.57-5.59, lift within 10% of 0.0104-0.0110) and 3D-1Z (Re =
// 20 in a square channel, 250 x 41 x 41: drag within 3% of 6.05-6.25), the
// shipped scenes as they are. About 70 s and 2 minutes on 2 cores.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"
#include "tests/validation/run_in_process.h"

using namespace morphoflow::testing;

namespace {

// The mean drag and lift coefficients of the steady end of a shipped scene's run.
std::pair<double, double> coefficients(const std::string& scene) {
  auto out = tempDir(scene);
  EXPECT_EQ(runInProcess(sceneFile("validation/" + scene + ".toml"), {"output.images=false", "output.video=false"}, out),
            0);
  std::ifstream in(out / "run.json");
  const nlohmann::json run = nlohmann::json::parse(in);
  std::filesystem::remove_all(out);
  const double cd = run["drag_coefficient_mean"].get<double>(), cl = run["lift_coefficient_mean"].get<double>();
  ::testing::Test::RecordProperty("drag_coefficient", std::to_string(cd));
  ::testing::Test::RecordProperty("lift_coefficient", std::to_string(cl));
  std::cout << scene << ": drag " << cd << ", lift " << cl << "\n";
  return {cd, cl};
}

}  // namespace

TEST(DfgValidation, Cylinder2D1DragWithin1PercentAndLiftWithin10) {
  const auto [cd, cl] = coefficients("dfg_2d_1");
  EXPECT_GE(cd, 5.57 * 0.99);
  EXPECT_LE(cd, 5.59 * 1.01);
  EXPECT_GE(cl, 0.0104 * 0.9);
  EXPECT_LE(cl, 0.0110 * 1.1);
}

TEST(DfgValidation, Cylinder3D1ZDragWithin3Percent) {
  const auto [cd, cl] = coefficients("dfg_3d_1z");
  EXPECT_GE(cd, 6.05 * 0.97);
  EXPECT_LE(cd, 6.25 * 1.03);
}
