// Galilean invariance of moving obstacles at full size: a cylinder towed
// through still fluid in a channel periodic along x feels the drag and
// lift of the same cylinder fixed in a uniform stream (tests/fluid/
// towed_body.h), at Re 40 (steady wake) and Re 100 (shedding), and a
// sphere the same way in 3D: the mean drag within 2%, the lift's swing
// within 5%. By default Re 40 alone, with 16 cells across the cylinder;
// MORPHOFLOW_FULL_VALIDATION=1 runs all three at full size (20 and 30
// cells across the cylinder at Re 40 and 100, 10 across the sphere; about
// 35 minutes).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/fluid/towed_body.h"
#include "tests/test_support.h"

using namespace morphoflow;
using namespace morphoflow::testing;

TEST(MovingValidation, TowedCylinderAtRe40) {
  const int cells = fullValidation() ? 20 : 16;
  const ForceSeries towed = towedBody<2>(true, 40.0, cells, 3.0), fixed = towedBody<2>(false, 40.0, cells, 3.0);
  const double a = meanOver(towed, towed.drag, 2.0, 3.0), b = meanOver(fixed, fixed.drag, 2.0, 3.0);
  std::printf("Re 40, mean drag coefficient over t in [2, 3]: towed %.4f, fixed %.4f\n", a, b);
  EXPECT_NEAR(a, b, 0.02 * b);
}

TEST(MovingValidation, TowedCylinderAtRe100) {
  if (!fullValidation()) GTEST_SKIP() << "MORPHOFLOW_FULL_VALIDATION=1 runs it (about 25 minutes)";
  // 30 cells across the cylinder, over t in [8, 11]: the street has
  // developed, and each body meets the wake it left a lap before (the
  // channel is periodic), in either frame.
  const int cells = 30;
  const ForceSeries towed = towedBody<2>(true, 100.0, cells, 11.0), fixed = towedBody<2>(false, 100.0, cells, 11.0);
  const double a = meanOver(towed, towed.drag, 8.0, 11.0), b = meanOver(fixed, fixed.drag, 8.0, 11.0);
  const double cell = 0.1 / cells;  // the time the body takes to cross a cell at U = 1
  const double la = amplitudeOver(towed, towed.lift, 8.0, 11.0, cell);
  const double lb = amplitudeOver(fixed, fixed.lift, 8.0, 11.0, cell);
  std::printf("Re 100 over t in [8, 11]: mean drag coefficient towed %.4f, fixed %.4f; lift amplitude %.4f, %.4f\n", a,
              b, la, lb);
  // Measured: 1.2% and 1.4% apart. With 20 cells over [5, 8] the mean drag
  // is 2.9% apart (7.9% with 10: it converges, at about order 1.5), the
  // towed one the lower.
  EXPECT_NEAR(a, b, 0.02 * b);
  EXPECT_GT(lb, 0.1) << "the fixed cylinder sheds";
  EXPECT_NEAR(la, lb, 0.05 * lb);
}

TEST(MovingValidation, TowedSphereAtRe100) {
  if (!fullValidation()) GTEST_SKIP() << "MORPHOFLOW_FULL_VALIDATION=1 runs it (about 5 minutes)";
  const ForceSeries towed = towedBody<3>(true, 100.0, 10, 1.5, 20, 8);
  const ForceSeries fixed = towedBody<3>(false, 100.0, 10, 1.5, 20, 8);
  const double a = meanOver(towed, towed.drag, 1.0, 1.5), b = meanOver(fixed, fixed.drag, 1.0, 1.5);
  std::printf("3D Re 100, mean drag coefficient over t in [1, 1.5]: towed %.4f, fixed %.4f\n", a, b);
  EXPECT_NEAR(a, b, 0.02 * b);
}
