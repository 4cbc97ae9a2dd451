// The GPU's explicit step for every two-species model against the CPU's
// (rd/models.h): each reaction term written twice must agree. A random state
// near the model's default, the model's own parameters and diffusion, 50
// steps at a tenth of the explicit diffusion limit (and of the fastest
// reaction rate); float against double.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "core/random.h"
#include "tests/gpu/gpu_context.h"
#include "gpu/compute_program.h"
#include "gpu/gpu_buffer.h"
#include "gpu/gpu_explicit_rd.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_models.h"
#include "gpu/gpu_newton_check.h"
#include "gpu/shader_source.h"
#include "rd/newton.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

using namespace morphoflow;

TEST(GpuModels, EveryTwoSpeciesReactionStepsAsOnTheCpu) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  int checked = 0;
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& info = m->info();
    if (info.species.size() != 2) continue;  // (the explicit kernel steps two species)
    ASSERT_FALSE(gpuReaction(info.name, GpuPrecision::Float).empty()) << info.name;
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

namespace {

// The pieces of Kim & Lin's Newton (kernels/newton.inc) for one cell, as a
// probe shader writes them: R(x0), J(x0), the dense solve of (I - h J) d = R,
// Newton from x0, the whole implicit step, and three double operations
// (a / b, and a * b + c held unfused).
const char* kNewtonProbe = R"glsl(
#define N NSPECIES
layout(std430, binding = 0) readonly buffer In { double xin[]; };
layout(std430, binding = 1) writeonly buffer Out { double o[]; };
uniform int n;
uniform int record;
uniform double h;
uniform double uniformP[12];
uniform uint clamped;
double p[NPARAMETERS];
void rates(double x[N], out double r[N]) { modelRates(x, p, r); }
void jacobian(double x[N], out double J[N * N]) { modelJacobian(x, p, J); }
struct NewtonResult { bool converged; int iterations; double residual; };
#define NS N
#define NT double
#define NEWTON_TOLERANCE 1e-12lf
#define NEWTON_TINY 1e-300lf
#define ARRAY_IN(name) double name[N]
#define ARRAY_OUT(name) out double name[N]
#define ARRAY_INOUT(name) inout double name[N]
#define MATRIX_INOUT(name) inout double name[N][N]
#define CONSTEXPR
#include "newton.inc"
void main() {
  const int i = flatIndex();
  if (i >= n) return;
  for (int k = 0; k < NPARAMETERS; ++k) p[k] = uniformP[k];
  double x0[N];
  for (int s = 0; s < N; ++s) x0[s] = xin[i * N + s];
  int at = i * record;
  double r[N];
  rates(x0, r);
  for (int s = 0; s < N; ++s) o[at++] = r[s];
  double J[N * N];
  jacobian(x0, J);
  for (int k = 0; k < N * N; ++k) o[at++] = J[k];
  double A[N][N];
  double d[N];
  for (int s = 0; s < N; ++s) {
    for (int t = 0; t < N; ++t) {
      precise double a = (s == t ? 1.0lf : 0.0lf) - h * J[s * N + t];
      A[s][t] = a;
    }
    d[s] = r[s];
  }
  o[at++] = solveDense(A, d) ? 1.0lf : 0.0lf;
  for (int s = 0; s < N; ++s) o[at++] = d[s];
  double x[N];
  for (int s = 0; s < N; ++s) x[s] = x0[s];
  NewtonResult nr = newtonFrom(x0, h, x, 0u, newtonMaxIterations());
  o[at++] = nr.converged ? 1.0lf : 0.0lf;
  for (int s = 0; s < N; ++s) o[at++] = x[s];
  NewtonResult ir = implicitReaction(x0, h, x, clamped);
  o[at++] = ir.converged ? 1.0lf : 0.0lf;
  for (int s = 0; s < N; ++s) o[at++] = x[s];
  precise double a = x0[0] + 1.0lf, b = x0[1] + 3.0lf;
  o[at++] = a / b;
  precise double m = a * b + x0[0];
  o[at++] = m;
}
)glsl";

// The probe for a model's kernels.
std::unique_ptr<ComputeProgram> probeProgram(const std::string& model) {
  const std::string prologue = gpuReaction(model, GpuPrecision::Double) + shaderSource("common.glsl");
  return std::make_unique<ComputeProgram>("rd_react.comp", prologue, [](const std::string&) {
    const std::string include = "#include \"newton.inc\"";
    std::string text = kNewtonProbe;
    return text.replace(text.find(include), include.size(), shaderSource("newton.inc"));
  });
}

const char* kPieces[] = {"rates", "jacobian", "dense solve", "newton", "implicit step", "a / b", "a * b + c"};

}  // namespace

// Each piece of Kim & Lin's Newton on the GPU against the CPU's, bitwise,
// for every model at 10 and 100 times its fastest rate: where the whole
// step differs on a driver (GpuRD.KimLinNewtonIsBitwiseTheCpusForEveryModel),
// this names the piece, and whether the driver's plain double arithmetic is
// IEEE's (NVIDIA's 580 driver on an H200: every piece differs, the inputs
// held at single precision; docs/gpu.md).
TEST(GpuModels, NewtonsPiecesAreBitwiseTheCpus) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  constexpr int kCells = 128;
  for (const ReactionModel* m : allModels()) {
    const ModelInfo& info = m->info();
    const int ns = m->species();
    RDSettings s;
    s.model = info.name;
    s.resolution = {16, 16};
    s.size = {16.0, 16.0};
    RDSolver<2> probe(s, *m);
    std::vector<double> p;
    for (size_t k = 0; k < info.parameters.size(); ++k) p.push_back(probe.parameter(int(k)));
    p.resize(ReactionModel::kMaxParameters, 0.0);
    std::vector<double> J(size_t(ns * ns));
    m->jacobian(info.initial.data(), p.data(), J.data());
    double rate = 1e-12;
    for (int r = 0; r < ns; ++r) {
      double row = 0;
      for (int c = 0; c < ns; ++c) row += std::abs(J[size_t(r * ns + c)]);
      rate = std::max(rate, row);
    }
    unsigned clamped = 0;
    for (int c : info.clamped) clamped |= 1u << c;
    const int record = ns + ns * ns + 1 + ns + 1 + ns + 1 + ns + 2;
    const int widths[] = {ns, ns * ns, 1 + ns, 1 + ns, 1 + ns, 1, 1};
    auto rates = [&](const double* y, double* r) { m->rates(y, p.data(), r); };
    auto jacobian = [&](const double* y, double* Jy) { m->jacobian(y, p.data(), Jy); };
    NewtonKernel<ReactionModel::kMaxSpecies, decltype(rates), decltype(jacobian)> kernel{ns, rates, jacobian};
    const std::unique_ptr<ComputeProgram> program = probeProgram(info.name);
    for (const double factor : {10.0, 100.0}) {
      const double h = factor / rate;
      std::vector<double> x0(size_t(kCells * ns));
      for (size_t i = 0; i < x0.size(); ++i) {
        const double v = info.initial[i % size_t(ns)];
        x0[i] = v + 0.1 * (1.0 + std::abs(v)) * (uniform01(5, i % size_t(ns), i / size_t(ns)) - 0.5);
      }
      // The CPU's record of each cell.
      std::vector<double> want;
      for (int c = 0; c < kCells; ++c) {
        const double* x = &x0[size_t(c * ns)];
        double r[ReactionModel::kMaxSpecies], Jc[ReactionModel::kMaxSpecies * ReactionModel::kMaxSpecies],
            A[ReactionModel::kMaxSpecies][ReactionModel::kMaxSpecies], d[ReactionModel::kMaxSpecies],
            y[ReactionModel::kMaxSpecies];
        rates(x, r);
        jacobian(x, Jc);
        want.insert(want.end(), r, r + ns);
        want.insert(want.end(), Jc, Jc + ns * ns);
        for (int a = 0; a < ns; ++a) {
          for (int b = 0; b < ns; ++b) A[a][b] = (a == b ? 1.0 : 0.0) - h * Jc[a * ns + b];
          d[a] = r[a];
        }
        want.push_back(kernel.solveDense(A, d) ? 1.0 : 0.0);
        want.insert(want.end(), d, d + ns);
        std::copy(x, x + ns, y);
        want.push_back(kernel.newtonFrom(x, h, y, 0u, kernel.newtonMaxIterations()).converged ? 1.0 : 0.0);
        want.insert(want.end(), y, y + ns);
        want.push_back(kernel.implicitReaction(x, h, y, clamped).converged ? 1.0 : 0.0);
        want.insert(want.end(), y, y + ns);
        const double a = x[0] + 1.0, b = x[1] + 3.0;
        want.insert(want.end(), {a / b, a * b + x[0]});
      }
      // The GPU's, and the pieces that differ: cells, the largest relative difference.
      program->use();
      GpuBuffer in = GpuBuffer::of(x0), out(want.size() * sizeof(double));
      setUniform(*program, "n", kCells);
      setUniform(*program, "record", record);
      setUniform(*program, "h", h);
      glUniform1dv(program->uniform("uniformP"), GLsizei(p.size()), p.data());
      glUniform1ui(program->uniform("clamped"), clamped);
      in.bind(0);
      out.bind(1);
      dispatchFlat(kCells, 0.0);
      const std::vector<double> got = out.read<double>(want.size());
      std::string report;
      for (int piece = 0, offset = 0; piece < 7; offset += widths[piece++]) {
        int cells = 0;
        double worst = 0;
        for (int c = 0; c < kCells; ++c) {
          bool differs = false;
          for (int k = 0; k < widths[piece]; ++k) {
            const double g = got[size_t(c * record + offset + k)], w = want[size_t(c * record + offset + k)];
            if (std::memcmp(&g, &w, sizeof g) == 0) continue;
            differs = true;
            worst = std::max(worst, std::abs(g - w) / std::max(std::abs(w), 1e-300));
          }
          cells += differs ? 1 : 0;
        }
        if (cells > 0)
          report += fmt::format("  {}: {} of {} cells differ (largest relative difference {:.3g})\n", kPieces[piece],
                                cells, kCells, worst);
      }
      EXPECT_TRUE(report.empty()) << info.name << " at " << factor << " x its fastest rate:\n" << report;
    }
  }
}

// The run's check of the driver's Newton (gpu/gpu_newton_check.h) passes for
// every model in both precisions on a driver whose arithmetic is right, so
// the GPU backend refuses Kim & Lin's integrator only where its roots would
// be wrong: the float Newton meets its own tolerance wherever the CPU's
// meets 1e-12, and its roots agree with the CPU's to 1e-4 of the step's change.
TEST(GpuModels, TheNewtonCheckPassesEveryModelOnASoundDriver) {
  if (const std::string why = gpuContextMissing(); !why.empty()) GTEST_SKIP() << why;
  for (GpuPrecision real : {GpuPrecision::Double, GpuPrecision::Float})
    for (const ReactionModel* m : allModels())
      EXPECT_EQ(gpuNewtonDefect(m->info().name, real), "") << m->info().name << " in " << precisionName(real);
}
