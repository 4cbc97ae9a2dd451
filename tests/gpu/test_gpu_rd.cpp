// The GPU's reaction-diffusion layer (in double, and in float where named)
// against the CPU's RDSolver: Kim & Lin's implicit reaction for every two-species model at
// time steps far beyond the explicit limit (where Newton needs its line
// search, continuation and restarts), each integrator's theta scheme, 2D and
// 3D, periodic and zero-flux walls.
#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "core/random.h"
#include "tests/gpu/gpu_context.h"
#include "gpu/gpu_layer_difference.h"
#include "gpu/gpu_models.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/cosine_lobe.h"
#include "rd/diffusion_tensor.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

using namespace morphoflow;

namespace {


// Steps both layers from the same random state near the model's default and
// returns the largest difference over the largest change (both species).
template <int D>
double relativeDifference(RDSettings s, const ReactionModel& m, double dt, int steps,
                          GpuPrecision real = GpuPrecision::Double) {
  RDSolver<D> cpu(s, m);
  const ModelInfo& info = m.info();
  const std::vector<std::vector<double>> start = perturbNearInitial<D>(&cpu, 3);
  GpuRDLayer<D> gpu(layerUpload(cpu), real);
  for (int n = 0; n < steps; ++n) {
    cpu.step(dt);
    gpu.step(dt);
    EXPECT_TRUE(gpu.lastStats().diffusion.converged) << info.name << " " << gpu.lastStats().diffusion.residual;
    if (real == GpuPrecision::Double) {
      EXPECT_EQ(gpu.lastStats().newton.failures, cpu.lastStats().newton.failures) << info.name;
    } else {
      EXPECT_LE(gpu.lastStats().newton.failures, cpu.lastStats().newton.failures) << info.name;
    }
  }
  const auto [worst, moved, apart] = layerDifference<D>(gpu, cpu, start);
  EXPECT_GT(moved, 1e-4) << info.name << ": the steps must change the state";
  return worst / moved;
}

}  // namespace

// Kim & Lin's implicit reaction alone (no diffusion), 10 steps at 10 and 100
// times the reaction's fastest local rate, where Newton needs its line
// search, continuation and restarts and some cells fail: the GPU's Newton
// (double, no fused multiply-adds) gives bitwise the CPU's roots, and fails
// in the same cells, for every model (two to five species).
TEST(GpuRD, KimLinNewtonIsBitwiseTheCpusForEveryModel) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  int checked = 0;
  for (const ReactionModel* m : allModels()) {
    ASSERT_FALSE(gpuReaction(m->info().name, GpuPrecision::Double).empty()) << m->info().name;
    RDSettings s;
    s.model = m->info().name;
    s.resolution = {24, 20};
    s.size = {24.0, 20.0};
    s.diffusion.assign(m->info().species.size(), 0.0);
    s.boundary = RDBoundary::Neumann;
    RDSolver<2> probe(s, *m);
    std::vector<double> p;
    for (size_t k = 0; k < m->info().parameters.size(); ++k) p.push_back(probe.parameter(int(k)));
    const size_t ns = m->info().species.size();
    std::vector<double> J(ns * ns);
    m->jacobian(m->info().initial.data(), p.data(), J.data());
    double rate = 1e-12;  // the largest row sum
    for (size_t r = 0; r < ns; ++r) {
      double row = 0;
      for (size_t c = 0; c < ns; ++c) row += std::abs(J[r * ns + c]);
      rate = std::max(rate, row);
    }
    for (double factor : {10.0, 100.0})
      EXPECT_EQ(relativeDifference<2>(s, *m, factor / rate, 10), 0.0) << m->info().name << " x" << factor;
    ++checked;
  }
  EXPECT_GE(checked, 14);
}

namespace {

// Gray-Scott through every integrator, 2D periodic and 3D zero-flux, on the
// GPU in `real` against the CPU: within `tolerance` of the change over the run.
void expectIntegratorsMatch(GpuPrecision real, double tolerance) {
  const ReactionModel& gs = *findModel("gray-scott");
  for (RDIntegrator integ : {RDIntegrator::ExplicitEuler, RDIntegrator::SemiImplicit, RDIntegrator::KimLin,
                             RDIntegrator::CrankNicolson}) {
    RDSettings s;
    s.model = "gray-scott";
    s.integrator = integ;
    s.resolution = {32, 32};
    s.size = {0.32, 0.32};
    s.diffusion = {2e-5, 1e-5};
    s.boundary = RDBoundary::Periodic;
    const double dt = integ == RDIntegrator::ExplicitEuler ? 0.5 : 5.0;
    EXPECT_LT(relativeDifference<2>(s, gs, dt, 20, real), tolerance) << int(integ);
    s.resolution = {12, 10, 8};
    s.size = {0.12, 0.10, 0.08};
    s.boundary = RDBoundary::Neumann;
    EXPECT_LT(relativeDifference<3>(s, gs, dt, 10, real), tolerance) << int(integ) << " 3D";
  }
}

}  // namespace

// With diffusion both sides solve to rd.tolerance (1e-8): the layers agree
// to a millionth of the change over the run.
TEST(GpuRD, EveryIntegratorMatchesTheCpuIn2DAnd3D) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  expectIntegratorsMatch(GpuPrecision::Double, 1e-6);
}

// In float (the default): every integrator within 5e-4 of the change over
// the run (measured 1.4e-6 explicit, at most 1.1e-4 implicit: the CPU's
// solves stop at 1e-8, the float ones at float's floor, 4e-6, and meet it),
// Kim & Lin's Newton at float's tolerance failing in no more cells than the CPU's.
TEST(GpuRD, EveryIntegratorMatchesTheCpuInFloat) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  expectIntegratorsMatch(GpuPrecision::Float, 5e-4);
}

// Dirichlet walls (ghost values in the implicit and the explicit parts), a
// parameter map, a fixed region and a frozen species: the GPU layer applies
// each as the CPU does (both solves at 1e-12, so the agreement is rounding).
TEST(GpuRD, MapsFixedCellsFrozenSpeciesAndDirichletWallsMatchTheCpu) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  const ReactionModel& gs = *findModel("gray-scott");
  for (RDIntegrator integ : {RDIntegrator::ExplicitEuler, RDIntegrator::KimLin, RDIntegrator::CrankNicolson}) {
    for (int variant = 0; variant < 3; ++variant) {
      RDSettings s;
      s.model = "gray-scott";
      s.integrator = integ;
      s.resolution = {32, 24};
      s.size = {0.32, 0.24};
      s.diffusion = {2e-5, 1e-5};
      s.tolerance = 1e-12;
      s.boundary = variant == 0 ? RDBoundary::Dirichlet : RDBoundary::Neumann;
      s.dirichletValues = {0.9, 0.2};
      if (variant == 2) s.frozen = {0};
      RDSolver<2> cpu(s, gs);
      std::vector<double> F(cpu.field(0).size()), fixedU(F.size(), 0.5), fixedV(F.size(), 0.25);
      std::vector<uint8_t> mask(F.size(), 0);
      for (size_t i = 0; i < F.size(); ++i) {
        const double x = double(i % 32) / 32;
        F[i] = 0.02 + 0.04 * x;
        mask[i] = i % 32 == 5 ? 1 : 0;  // a fixed column
        for (int k = 0; k < 2; ++k)
          cpu.field(k)[i] = (k == 0 ? 1.0 : 0.0) + 0.3 * (uniform01(5, uint64_t(k), i) - 0.5) * (k == 0 ? -1 : 1);
      }
      if (variant == 1) {
        cpu.setParameterField(0, F);
        cpu.setFixedCells({mask, mask}, {fixedU, fixedV});
      }
      GpuRDLayer<2> gpu(layerUpload(cpu));
      const double dt = integ == RDIntegrator::ExplicitEuler ? 0.5 : 5.0;
      std::vector<double> start = cpu.field(1).values();
      for (int n = 0; n < 20; ++n) {
        cpu.step(dt);
        gpu.step(dt);
      }
      double worst = 0, moved = 0;
      for (int k = 0; k < 2; ++k) {
        const std::vector<double> g = gpu.download(k);
        for (size_t i = 0; i < g.size(); ++i) worst = std::max(worst, std::abs(g[i] - cpu.field(k)[i]));
      }
      for (size_t i = 0; i < start.size(); ++i) moved = std::max(moved, std::abs(cpu.field(1)[i] - start[i]));
      EXPECT_LT(worst, 1e-9) << "integrator " << int(integ) << " variant " << variant;
      EXPECT_GT(moved, 1e-3) << "integrator " << int(integ) << " variant " << variant;
    }
  }
}

namespace {

// A fixed tensor whose principal direction turns across the grid (every
// mixed term nonzero somewhere, in each plane in 3D).
template <int D>
DiffusionTensorSpec<D> turningTensor(const IVec<D>& cells) {
  DiffusionTensorSpec<D> t;
  size_t n = 1;
  for (int a = 0; a < D; ++a) n *= size_t(cells[a]);
  for (int a = 0; a < D; ++a) t.direction[size_t(a)].resize(n);
  t.lambda1.assign(n, 1.5);
  t.lambda2.assign(n, 0.5);
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    const double th = 3.0 * double(k[0]) / cells[0] + 2.0 * double(k[1]) / cells[1];
    t.direction[0][i] = std::cos(th);
    t.direction[1][i] = std::sin(th);
    if constexpr (D == 3) t.direction[2][i] = 0.5 + double(k[2]) / cells[2];
  });
  return t;
}

// Gray-Scott on `cells` cells of 0.01, solves at 1e-12, and a random start (seed `seed`).
template <int D>
RDSettings grayScottBox(RDIntegrator integ, RDBoundary boundary, const IVec<D>& cells) {
  RDSettings s;
  s.model = "gray-scott";
  s.integrator = integ;
  s.resolution.clear();
  s.size.clear();
  for (int a = 0; a < D; ++a) {
    s.resolution.push_back(cells[a]);
    s.size.push_back(0.01 * cells[a]);
  }
  s.diffusion = {2e-5, 1e-5};
  s.tolerance = 1e-12;
  s.boundary = boundary;
  s.dirichletValues = {0.9, 0.1};
  return s;
}
template <int D>
void randomStart(RDSolver<D>* rd, uint64_t seed) {
  for (int k = 0; k < 2; ++k)
    for (size_t i = 0; i < rd->field(k).size(); ++i)
      rd->field(k)[i] = (k == 0 ? 1.0 : 0.0) + 0.3 * (uniform01(seed, uint64_t(k), i) - 0.5) * (k == 0 ? -1 : 1);
}

template <int D>
double tensorDifference(RDIntegrator integ, RDBoundary boundary, const IVec<D>& cells, double shape = 0.0) {
  RDSolver<D> cpu(grayScottBox<D>(integ, boundary, cells), *findModel("gray-scott"));
  randomStart(&cpu, 9);
  DiffusionTensorSpec<D> tensor = turningTensor<D>(cells);
  tensor.shape = shape;  // eq. 18-19: the diffusivities follow species 1's gradient
  tensor.shapeSpecies = 1;
  cpu.setDiffusionTensor(tensor);
  GpuRDLayer<D> gpu(layerUpload(cpu));
  const double dt = integ == RDIntegrator::ExplicitEuler ? 0.2 : 5.0;
  for (int n = 0; n < 10; ++n) {
    cpu.step(dt);
    gpu.step(dt);
  }
  double worst = 0;
  for (int k = 0; k < 2; ++k) {
    const std::vector<double> g = gpu.download(k);
    for (size_t i = 0; i < g.size(); ++i) worst = std::max(worst, std::abs(g[i] - cpu.field(k)[i]));
  }
  return worst;
}

}  // namespace

// A fixed diffusion tensor (seed 004 eq. 11-17: the axis faces and the mixed
// terms) in 2D and 3D, periodic and walled, explicit and implicit: the GPU
// layer diffuses as the CPU's (solves at 1e-12).
TEST(GpuRD, AFixedDiffusionTensorMatchesTheCpuIn2DAnd3D) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (RDIntegrator integ : {RDIntegrator::ExplicitEuler, RDIntegrator::KimLin, RDIntegrator::CrankNicolson})
    for (RDBoundary b : {RDBoundary::Periodic, RDBoundary::Neumann}) {
      EXPECT_LT(tensorDifference<2>(integ, b, IVec<2>(24, 20)), 1e-9) << int(integ) << " " << int(b);
      EXPECT_LT(tensorDifference<3>(integ, b, IVec<3>(10, 8, 6)), 1e-9) << int(integ) << " " << int(b) << " 3D";
    }
}

// The same with the shape term (seed 004 eq. 18-19: the principal
// diffusivities follow a species' gradient), the tensor rebuilt on the GPU
// every step, walled, periodic and Dirichlet.
TEST(GpuRD, AShapedDiffusionTensorRebuiltEachStepMatchesTheCpu) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (RDIntegrator integ : {RDIntegrator::ExplicitEuler, RDIntegrator::KimLin, RDIntegrator::CrankNicolson})
    for (RDBoundary b : {RDBoundary::Periodic, RDBoundary::Neumann, RDBoundary::Dirichlet}) {
      EXPECT_LT(tensorDifference<2>(integ, b, IVec<2>(24, 20), 0.4), 1e-9) << int(integ) << " " << int(b);
      EXPECT_LT(tensorDifference<3>(integ, b, IVec<3>(10, 8, 6), 0.4), 1e-9) << int(integ) << " " << int(b) << " 3D";
    }
}

namespace {

template <int D>
double lobeDifference(RDIntegrator integ, RDBoundary boundary, const IVec<D>& cells, bool witkinKass,
                      double* fromIsotropic) {
  const RDSettings s = grayScottBox<D>(integ, boundary, cells);
  RDSolver<D> cpu(s, *findModel("gray-scott")), iso(s, *findModel("gray-scott"));
  randomStart(&cpu, 11);
  randomStart(&iso, 11);
  CosineLobeSpec spec;
  spec.witkinKass = witkinKass;
  spec.speeds = witkinKass ? std::vector<double>{1.5, 0.3} : std::vector<double>{1.0, 0.2, 0.6};
  spec.theta0.resize(cpu.field(0).size());
  for (size_t i = 0; i < spec.theta0.size(); ++i) spec.theta0[i] = 0.3 + 0.001 * double(i % 97);
  cpu.setCosineLobes(spec);
  GpuRDLayer<D> gpu(layerUpload(cpu));
  const double dt = integ == RDIntegrator::ExplicitEuler ? 0.2 : integ == RDIntegrator::CrankNicolson ? 1.0 : 5.0;
  for (int n = 0; n < 5; ++n) {
    cpu.step(dt);
    iso.step(dt);
    gpu.step(dt);
  }
  double worst = 0, lobe = 0;
  for (int k = 0; k < 2; ++k) {
    const std::vector<double> g = gpu.download(k);
    for (size_t i = 0; i < g.size(); ++i) {
      worst = std::max(worst, std::abs(g[i] - cpu.field(k)[i]));
      lobe = std::max(lobe, std::abs(cpu.field(k)[i] - iso.field(k)[i]));
    }
  }
  *fromIsotropic = lobe;
  return worst;
}

}  // namespace

// Kim & Lin's cosine lobes (eq. 15 and 16, a theta0 field), rebuilt on the
// GPU from each step's state: the GPU layer agrees with the CPU's (solves at
// 1e-12) in 2D and 3D, periodic, walled and Dirichlet, with three
// integrators, while the lobes move the result far from isotropic diffusion.
// After one step the two agree to 2e-12; a(theta) turns abruptly with the
// gradient's direction where the gradient nearly vanishes, which amplifies
// the solves' last digits step by step (measured up to 1.4e-7 after five
// Kim & Lin steps beside a Dirichlet wall), hence 1e-6.
TEST(GpuRD, CosineLobesMatchTheCpuIn2DAnd3D) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (RDIntegrator integ : {RDIntegrator::ExplicitEuler, RDIntegrator::KimLin, RDIntegrator::CrankNicolson})
    for (RDBoundary b : {RDBoundary::Periodic, RDBoundary::Neumann, RDBoundary::Dirichlet})
      for (bool wk : {false, true}) {
        double lobe2 = 0, lobe3 = 0;
        EXPECT_LT(lobeDifference<2>(integ, b, IVec<2>(24, 20), wk, &lobe2), 1e-6)
            << int(integ) << " " << int(b) << " " << wk;
        EXPECT_LT(lobeDifference<3>(integ, b, IVec<3>(10, 8, 6), wk, &lobe3), 1e-6)
            << int(integ) << " " << int(b) << " " << wk << " 3D";
        EXPECT_GT(lobe2, 1e-4) << "the lobes must matter";
        EXPECT_GT(lobe3, 1e-4) << "the lobes must matter";
      }
}
