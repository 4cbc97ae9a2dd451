// The GPU's explicit step for every two-species model against the CPU's
// (rd/models.h): each reaction term written twice must agree. A random state
// near the model's default, the model's own parameters and diffusion, 50
// steps at a tenth of the explicit diffusion limit (and of the fastest
// reaction rate); float against double.
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "gpu_context.h"
#include "gpu/gpu_explicit_rd.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

using namespace morphoflow;

TEST(GpuModels, EveryTwoSpeciesReactionStepsAsOnTheCpu) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  int checked = 0;
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& info = m->info();
    if (info.species.size() != 2) {
      EXPECT_TRUE(gpuReaction(info.name).empty()) << info.name;  // refused: the shader steps two species
      continue;
    }
    ASSERT_FALSE(gpuReaction(info.name).empty()) << info.name;
    RDSettings s;
    s.model = info.name;
    s.resolution = {32, 24};
    s.size = {32.0, 24.0};
    s.integrator = RDIntegrator::ExplicitEuler;
    RDSolver<2> cpu(s, *m);
    std::vector<float> start[2];
    for (int k = 0; k < 2; ++k)
      for (size_t i = 0; i < cpu.field(k).size(); ++i) {
        const double x = info.initial[size_t(k)] + 0.05 * (uniform01(7, uint64_t(k), i) - 0.5) + 0.05;
        start[k].push_back(float(x));
        cpu.field(k)[i] = double(float(x));
      }
    std::vector<double> params;
    for (size_t k = 0; k < info.parameters.size(); ++k) params.push_back(cpu.parameter(int(k)));
    // A tenth of the diffusion limit and of the reaction's fastest local rate (the Jacobian's row sums).
    double rate = 1e-12;
    for (size_t i = 0; i < cpu.field(0).size(); ++i) {
      const double x[2] = {cpu.field(0)[i], cpu.field(1)[i]};
      double J[4];
      m->jacobian(x, params.data(), J);
      rate = std::max({rate, std::abs(J[0]) + std::abs(J[1]), std::abs(J[2]) + std::abs(J[3])});
    }
    const double dt = 0.1 * std::min(cpu.explicitDiffusionLimit(), 1.0 / rate);
    GpuExplicitRD gpu(s, cpu.diffusion(), params, info.clamped, start[0], start[1]);
    for (int n = 0; n < 50; ++n) {
      cpu.step(dt);
      gpu.step(dt);
    }
    for (int k = 0; k < 2; ++k) {
      const std::vector<float> g = gpu.download(k);
      double worst = 0, scale = 0, moved = 0;
      for (size_t i = 0; i < g.size(); ++i) {
        worst = std::max(worst, std::abs(double(g[i]) - cpu.field(k)[i]));
        scale = std::max(scale, std::abs(cpu.field(k)[i]));
        moved = std::max(moved, std::abs(cpu.field(k)[i] - double(start[k][i])));
      }
      EXPECT_LT(worst, 1e-5 * (1.0 + scale) + 1e-3 * moved) << info.name << " species " << info.species[size_t(k)];
      EXPECT_GT(moved, 1e-6) << info.name << ": the step must change the state for the check to mean anything";
    }
    ++checked;
  }
  EXPECT_GE(checked, 11);
}
