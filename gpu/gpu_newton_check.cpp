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

std::string check(const ReactionModel& m, GpuPrecision real) {
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
  GpuRDLayer<2> gpu(layerUpload(cpu), real);
  const double dt = 10.0 / rate;
  cpu.step(dt);
  gpu.step(dt);
  // double: the CPU's roots to rounding, in every cell. float: to 1e-4 of
  // the step's change, but for at most 1 cell in 32, where a model with
  // several roots near a fold (the three-layer Oregonator's) lets float's
  // rounding pick the other branch; a driver whose arithmetic is wrong
  // differs nearly everywhere (docs/gpu.md, "Drivers").
  const bool single = real == GpuPrecision::Float;
  const LayerDifference d = layerDifference<2>(gpu, cpu, start, single ? 1e-4 : 1e-9);
  const size_t cells = cpu.field(0).size(), allowed = single ? cells / 32 : 0;
  const int gpuFailures = gpu.lastStats().newton.failures, cpuFailures = cpu.lastStats().newton.failures;
  if (d.apart > allowed || gpuFailures > cpuFailures)
    return fmt::format(
        "its Newton failed in {} of {} cells (the CPU's in {}) and its roots differ from the CPU's in {} cells, by "
        "up to {:.2g} of the step's change",
        gpuFailures, cells, cpuFailures, d.apart, d.moved > 0 ? d.worst / d.moved : d.worst);
  return "";
}

}  // namespace

std::string gpuNewtonDefect(const std::string& model, GpuPrecision real) {
  static std::map<std::pair<std::string, GpuPrecision>, std::string> checked;
  auto it = checked.find({model, real});
  if (it == checked.end()) {
    const ReactionModel* m = findModel(model);
    it = checked.emplace(std::pair{model, real}, m ? check(*m, real) : std::string()).first;
  }
  return it->second;
}

}  // namespace morphoflow
