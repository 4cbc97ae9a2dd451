#include "gpu/gpu_newton_check.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "gpu/gpu_layer_difference.h"
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
  const std::vector<std::vector<double>> start = perturbNearInitial<2>(&cpu, 11);
  GpuRDLayer<2> gpu(layerUpload(cpu));
  const double dt = 10.0 / rate;
  cpu.step(dt);
  gpu.step(dt);
  const auto [worst, moved] = layerDifference<2>(gpu, cpu, start);
  const int gpuFailures = gpu.lastStats().newton.failures, cpuFailures = cpu.lastStats().newton.failures;
  if (!(worst <= 1e-9 * moved) || gpuFailures > cpuFailures)
    return fmt::format(
        "its Newton failed in {} of {} cells (the CPU's in {}) and its roots differ from the CPU's by {:.2g} of "
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
