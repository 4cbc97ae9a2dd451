#include "gpu/gpu_newton_check.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "core/random.h"
#include "gpu/gpu_rd_layer.h"
#include "rd/layer_upload.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

namespace {

std::string check(const ReactionModel& m) {
  const ModelInfo& info = m.info();
  const int ns = m.species();
  RDSettings s;
  s.model = info.name;
  s.resolution = {16, 8};
  s.size = {16.0, 8.0};
  s.diffusion.assign(size_t(ns), 0.0);  // the reaction alone
  s.boundary = RDBoundary::Neumann;
  s.integrator = RDIntegrator::KimLin;
  RDSolver<2> cpu(s, m);
  std::vector<double> p;
  for (size_t k = 0; k < info.parameters.size(); ++k) p.push_back(cpu.parameter(int(k)));
  std::vector<double> J(size_t(ns * ns));
  m.jacobian(info.initial.data(), p.data(), J.data());
  double rate = 1e-12;  // the largest row sum of the Jacobian at the rest state
  for (int r = 0; r < ns; ++r) {
    double row = 0;
    for (int c = 0; c < ns; ++c) row += std::abs(J[size_t(r * ns + c)]);
    rate = std::max(rate, row);
  }
  std::vector<std::vector<double>> start(static_cast<size_t>(ns));
  for (int k = 0; k < ns; ++k) {
    const double v = info.initial[size_t(k)];
    for (size_t i = 0; i < cpu.field(k).size(); ++i)
      cpu.field(k)[i] = v + 0.1 * (1.0 + std::abs(v)) * (uniform01(11, uint64_t(k), i) - 0.5);
    start[size_t(k)] = cpu.field(k).values();
  }
  GpuRDLayer<2> gpu(layerUpload(cpu));
  const double dt = 10.0 / rate;
  cpu.step(dt);
  gpu.step(dt);
  double worst = 0, moved = 0;
  for (int k = 0; k < ns; ++k) {
    const std::vector<double> g = gpu.download(k);
    for (size_t i = 0; i < g.size(); ++i) {
      worst = std::max(worst, std::abs(g[i] - cpu.field(k)[i]));
      moved = std::max(moved, std::abs(cpu.field(k)[i] - start[size_t(k)][i]));
    }
  }
  const int gpuFailures = gpu.lastStats().newton.failures, cpuFailures = cpu.lastStats().newton.failures;
  if (!(worst <= 1e-9 * moved) || gpuFailures > cpuFailures)
    return fmt::format("its Newton failed in {} of {} cells (the CPU's in {}) and its roots differ from the CPU's by {:.2g} of "
                       "the step's change",
                       gpuFailures, cpu.cells()[0] * cpu.cells()[1], cpuFailures, moved > 0 ? worst / moved : worst);
  return "";
}

}  // namespace

std::string gpuNewtonDefect(const std::string& model) {
  static std::map<std::string, std::string> checked;
  auto it = checked.find(model);
  if (it == checked.end()) {
    const ReactionModel* m = findModel(model);
    it = checked.emplace(model, m ? check(*m) : std::string()).first;
  }
  return it->second;
}

}  // namespace morphoflow
