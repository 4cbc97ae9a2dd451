// Helpers for tests of the reaction-diffusion solver.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/laplace_system.h"
#include "rd/rd_solver.h"

namespace morphoflow::testing {

struct MassAndNorm {
  double mass0 = 0, mass = 0;    // sum of species 0 before and after
  double norm0 = 0, norm = 0;    // its L2 norm before and after
};

inline double speciesMass(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  return m;
}

// Steps rd `steps` times by dt, expecting species 0's L2 norm never to grow
// (to round-off) on any step; afterStep() runs after each step. Stops at a
// fatal failure inside afterStep.
template <int D, class AfterStep>
MassAndNorm stepExpectingDecay(RDSolver<D>& rd, double dt, int steps, const std::string& label,
                               AfterStep&& afterStep) {
  MassAndNorm r;
  r.mass0 = speciesMass(rd.field(0).values());
  r.norm0 = r.norm = norm2(rd.field(0).values());
  for (int i = 0; i < steps; ++i) {
    rd.step(dt);
    afterStep();
    if (::testing::Test::HasFatalFailure()) return r;
    const double e = norm2(rd.field(0).values());
    EXPECT_LE(e, r.norm * (1 + 1e-12)) << label << "step " << i;
    r.norm = e;
  }
  r.mass = speciesMass(rd.field(0).values());
  return r;
}

}  // namespace morphoflow::testing
