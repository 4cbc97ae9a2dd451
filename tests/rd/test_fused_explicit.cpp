// The fused explicit step (rd/fused_explicit.h): bitwise the same fields for
// any rows per task, thread count and lane width; a Fourier mode of pure
// diffusion decays by exactly the discrete amplification per step; and
// Gray-Scott, Turing (clamped) and a five-species model follow RDSolver's
// double-precision explicit step to float rounding.
#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "core/random.h"
#include "core/simd_dispatch.h"
#include "rd/fused_explicit.h"
#include "rd/generalized_diffusion.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

using namespace morphoflow;

namespace {

template <int D>
std::unique_ptr<FusedExplicitRD<D>> pearson(const IVec<D>& n, bool periodic) {
  auto e = FusedExplicitRD<D>::create("gray-scott", n, 1.0, periodic, {0.2, 0.1}, {0.04, 0.06});
  for (int s = 0; s < 2; ++s)
    for (size_t i = 0; i < e->field(s).size(); ++i)
      e->field(s)[i] = float((s == 0 ? 0.6 : 0.2) + 0.4 * (uniform01(11, uint64_t(s), i) - 0.5));
  return e;
}

}  // namespace

TEST(FusedExplicit, TheSameFieldsForAnyTilingThreadsAndLanes) {
  for (bool periodic : {true, false}) {
    std::vector<std::vector<float>> reference;
    for (int variant = 0; variant < 5; ++variant) {
      ThreadLimit limit(variant == 1 ? 1 : 2);
      setUseAvx2(variant != 2);
      auto e = pearson<2>(IVec<2>(37, 29), periodic);
      if (variant == 3) e->setRowsPerTask(1);
      if (variant == 4) e->setRowsPerTask(7);
      e->step(0.5, 40);
      if (variant == 0) reference = {e->field(0), e->field(1)};
      else
        for (int s = 0; s < 2; ++s) ASSERT_EQ(e->field(s), reference[size_t(s)]) << "variant " << variant;
    }
    setUseAvx2(true);
    std::vector<std::vector<float>> ref3;
    for (int variant = 0; variant < 3; ++variant) {
      ThreadLimit limit(variant == 1 ? 1 : 2);
      setUseAvx2(variant != 2);
      auto e = pearson<3>(IVec<3>(13, 11, 9), periodic);
      e->step(0.3, 10);
      if (variant == 0) ref3 = {e->field(0), e->field(1)};
      else
        for (int s = 0; s < 2; ++s) ASSERT_EQ(e->field(s), ref3[size_t(s)]) << "3D variant " << variant;
    }
    setUseAvx2(true);
  }
}

// Diffusion alone (Gray-Scott with F = k = 0 and v = 0 leaves u' = d lap u):
// cos(2 pi m x / n) decays by 1 - 4 dt d sin^2(pi m / n) per step.
TEST(FusedExplicit, AFourierModeDecaysByTheDiscreteAmplification) {
  const int n = 64, m = 5, steps = 50;
  const double d = 0.3, dt = 0.5;
  auto e = FusedExplicitRD<2>::create("gray-scott", IVec<2>(n, 8), 1.0, true, {d, d}, {0.0, 0.0});
  for (size_t i = 0; i < e->field(0).size(); ++i) e->field(0)[i] = float(std::cos(2 * M_PI * m * double(i % n) / n));
  e->step(dt, steps);
  const double g = std::pow(1.0 - 4.0 * dt * d * std::pow(std::sin(M_PI * m / n), 2), steps);
  for (size_t i = 0; i < e->field(0).size(); ++i)
    ASSERT_NEAR(e->field(0)[i], g * std::cos(2 * M_PI * m * double(i % n) / n), 2e-6) << i;
}

TEST(FusedExplicit, FollowsTheDoubleStepToFloatRounding) {
  struct Case {
    const char* model;
    double dt;
  };
  for (const Case& c : {Case{"gray-scott", 0.5}, Case{"turing", 0.2}, Case{"meinhardt-lateral", 0.05}}) {
    const ReactionModel& model = *findModel(c.model);
    const ModelInfo& info = model.info();
    RDSettings s;
    s.model = c.model;
    s.resolution = {32, 24};
    s.size = {32.0, 24.0};
    s.integrator = RDIntegrator::ExplicitEuler;
    RDSolver<2> rd(s, model);
    auto e = FusedExplicitRD<2>::create(c.model, IVec<2>(32, 24), 1.0, true, info.diffusion, {});
    ASSERT_TRUE(e) << c.model;
    for (int sp = 0; sp < rd.species(); ++sp)
      for (size_t i = 0; i < rd.field(sp).size(); ++i) {
        const float v = float(info.initial[size_t(sp)] * (1.0 + 0.05 * (uniform01(5, uint64_t(sp), i) - 0.5)));
        rd.field(sp)[i] = v;
        e->field(sp)[i] = v;
      }
    for (int k = 0; k < 20; ++k) rd.step(c.dt);
    e->step(c.dt, 20);
    for (int sp = 0; sp < rd.species(); ++sp) {
      double scale = 1e-12;
      for (double v : rd.field(sp).values()) scale = std::max(scale, std::abs(v));
      for (size_t i = 0; i < rd.field(sp).size(); ++i)
        ASSERT_NEAR(e->field(sp)[i], rd.field(sp)[i], 2e-5 * scale) << c.model << " species " << sp << " cell " << i;
    }
  }
}

// McGraw's 5 x 5 kernel in place of the Laplacian: bitwise across lanes,
// tiling and threads, and RDSolver's double explicit step with the same
// operator to float rounding.
TEST(FusedExplicit, TheGeneralizedKernelMatchesRDSolversOperator) {
  const int n = 40;
  const double h = 2.2;
  auto op = std::make_shared<GeneralizedDiffusion>(*kramersMoyalPreset("c"), n, n, h);
  RDSettings s;
  s.model = "gray-scott";
  s.resolution = {n, n};
  s.size = {n * h, n * h};
  s.diffusion = {0.2 * h * h, 0.1 * h * h};
  s.integrator = RDIntegrator::ExplicitEuler;
  RDSolver<2> rd(s, *findModel("gray-scott"));
  rd.setGeneralizedDiffusion(op, {});
  std::vector<std::vector<float>> reference;
  for (int variant = 0; variant < 5; ++variant) {
    ThreadLimit limit(variant == 1 ? 1 : 2);
    setUseAvx2(variant != 2);
    setUseAvx512(variant != 4);
    auto e = FusedExplicitRD<2>::create("gray-scott", IVec<2>(n, n), h, true, s.diffusion, {});
    e->setKernel(op->kernel(), {});
    if (variant == 3) e->setRowsPerTask(3);
    for (int sp = 0; sp < 2; ++sp)
      for (size_t i = 0; i < e->field(sp).size(); ++i) {
        const float v = float((sp == 0 ? 0.6 : 0.2) + 0.4 * (uniform01(13, uint64_t(sp), i) - 0.5));
        e->field(sp)[i] = v;
        if (variant == 0) rd.field(sp)[i] = v;
      }
    e->step(0.5, 30);
    if (variant == 0) {
      reference = {e->field(0), e->field(1)};
      for (int k = 0; k < 30; ++k) rd.step(0.5);
      for (int sp = 0; sp < 2; ++sp)
        for (size_t i = 0; i < rd.field(sp).size(); ++i)
          ASSERT_NEAR(e->field(sp)[i], rd.field(sp)[i], 2e-5) << sp << " " << i;
    } else {
      for (int sp = 0; sp < 2; ++sp) ASSERT_EQ(e->field(sp), reference[size_t(sp)]) << "variant " << variant;
    }
  }
  setUseAvx2(true);
  setUseAvx512(true);
}

// Rows longer than the kernel's chunks (32 vectors), with a ragged end, and
// a species on the Laplacian beside one on the kernel: the same bits with
// AVX-512, AVX2 and SSE lanes and with one thread.
TEST(FusedExplicit, TheGeneralizedKernelsChunksGiveTheSameBits) {
  const IVec<2> n(16 * 33 + 11, 6);
  const double h = 2.2;
  GeneralizedDiffusion op(*kramersMoyalPreset("d"), n[0], n[1], h);
  std::vector<std::vector<float>> reference;
  for (int variant = 0; variant < 4; ++variant) {
    ThreadLimit limit(variant == 3 ? 1 : 2);
    setUseAvx2(variant != 2);
    setUseAvx512(variant == 0 || variant == 3);
    auto e = FusedExplicitRD<2>::create("gray-scott", n, h, true, {0.2 * h * h, 0.1 * h * h}, {});
    e->setKernel(op.kernel(), {1});
    for (int sp = 0; sp < 2; ++sp)
      for (size_t i = 0; i < e->field(sp).size(); ++i)
        e->field(sp)[i] = float((sp == 0 ? 0.6 : 0.2) + 0.4 * (uniform01(17, uint64_t(sp), i) - 0.5));
    e->step(0.3, 12);
    if (variant == 0) reference = {e->field(0), e->field(1)};
    else
      for (int sp = 0; sp < 2; ++sp) ASSERT_EQ(e->field(sp), reference[size_t(sp)]) << "variant " << variant;
  }
  setUseAvx2(true);
  setUseAvx512(true);
}

namespace {

// The fields after `steps` steps of a layer started from the same noise,
// with `stepsPerPass` steps per blocked pass over slabs of `slices`.
template <int D>
std::vector<std::vector<float>> blocked(const std::string& model, const IVec<D>& n, bool periodic, int kernelSpecies,
                                        int stepsPerPass, size_t slices, int threads, double dt, int steps) {
  ThreadLimit limit(threads);
  const ModelInfo info = findModel(model)->info();
  auto e = FusedExplicitRD<D>::create(model, n, 1.0, periodic, info.diffusion, {});
  if constexpr (D == 2)
    if (kernelSpecies >= 0)
      e->setKernel(GeneralizedDiffusion(*kramersMoyalPreset("d"), n[0], n[1], 1.0).kernel(), {kernelSpecies});
  for (int s = 0; s < e->species(); ++s)
    for (size_t i = 0; i < e->field(s).size(); ++i)
      e->field(s)[i] = float(info.initial[size_t(s)] * (1.0 + 0.2 * (uniform01(19, uint64_t(s), i) - 0.5)));
  e->setTemporalBlocking(stepsPerPass, slices);
  e->step(dt, steps);
  std::vector<std::vector<float>> f;
  for (int s = 0; s < e->species(); ++s) f.push_back(e->field(s));
  return f;
}

}  // namespace

// Temporal blocking (several steps per pass over slabs of rows or planes,
// each with its halo recomputed) gives the fields of as many single steps,
// bitwise: for any steps per pass (a remainder included), slab height (one
// slice, more than the grid, halos wider than the grid), thread count,
// boundary, dimension, the 5 x 5 kernel's wider reach and a model on double lanes.
TEST(FusedExplicit, TemporalBlockingGivesTheBitsOfSingleSteps) {
  struct Blocking {
    int steps;
    size_t slices;
    int threads;
  };
  const std::vector<Blocking> variants = {{2, 1, 2}, {3, 5, 1}, {8, 4, 2}, {5, 64, 2}, {23, 7, 2}, {4, 3, 1}};
  for (bool periodic : {true, false}) {
    const auto ref = blocked<2>("gray-scott", IVec<2>(37, 29), periodic, -1, 1, 0, 2, 0.5, 23);
    for (const Blocking& b : variants)
      ASSERT_EQ(blocked<2>("gray-scott", IVec<2>(37, 29), periodic, -1, b.steps, b.slices, b.threads, 0.5, 23), ref)
          << "2D periodic " << periodic << ", " << b.steps << " steps a pass, " << b.slices << " rows a task";
    const auto ref3 = blocked<3>("gray-scott", IVec<3>(13, 11, 9), periodic, -1, 1, 0, 2, 0.3, 10);
    for (const Blocking& b : {Blocking{2, 1, 2}, Blocking{3, 2, 1}, Blocking{4, 4, 2}, Blocking{10, 20, 2}})
      ASSERT_EQ(blocked<3>("gray-scott", IVec<3>(13, 11, 9), periodic, -1, b.steps, b.slices, b.threads, 0.3, 10), ref3)
          << "3D periodic " << periodic << ", " << b.steps << " steps a pass, " << b.slices << " planes a task";
    const auto refLateral = blocked<2>("meinhardt-lateral", IVec<2>(21, 17), periodic, -1, 1, 0, 2, 0.05, 9);
    ASSERT_EQ(blocked<2>("meinhardt-lateral", IVec<2>(21, 17), periodic, -1, 4, 3, 2, 0.05, 9), refLateral);
  }
  // The kernel reaches two rows: species 1 on it, species 0 on the Laplacian.
  const auto ref5 = blocked<2>("gray-scott", IVec<2>(45, 20), true, 1, 1, 0, 2, 0.3, 12);
  for (const Blocking& b : {Blocking{3, 3, 2}, Blocking{4, 16, 1}, Blocking{12, 1, 2}})
    ASSERT_EQ(blocked<2>("gray-scott", IVec<2>(45, 20), true, 1, b.steps, b.slices, b.threads, 0.3, 12), ref5)
        << "5 x 5 kernel, " << b.steps << " steps a pass, " << b.slices << " rows a task";
}

// The automatic choice: no blocking while the state stays in cache, several
// steps a pass beyond it (then the same bits as single steps).
TEST(FusedExplicit, BlockingIsChosenForStatesBeyondTheCache) {
  EXPECT_EQ(FusedExplicitRD<2>::create("gray-scott", IVec<2>(1024, 1024), 1.0, true, {0.2, 0.1}, {})->stepsPerPass(),
            1);
  EXPECT_EQ(FusedExplicitRD<3>::create("gray-scott", IVec<3>(128, 128, 128), 1.0, true, {0.2, 0.1}, {})->stepsPerPass(),
            1);
  const IVec<2> big(2048, 2048);
  EXPECT_GT(FusedExplicitRD<2>::create("gray-scott", big, 1.0, true, {0.2, 0.1}, {})->stepsPerPass(), 1);
  EXPECT_EQ(blocked<2>("gray-scott", big, true, -1, 0, 0, 2, 0.5, 11),
            blocked<2>("gray-scott", big, true, -1, 1, 0, 2, 0.5, 11));
}
