#include "rd/layer_stepper.h"

#include <algorithm>

namespace morphoflow {

void RDRunStats::add(const RDStepStats& st) {
  newton.merge(st.newton);
  diffusionIterations += st.diffusion.iterations;
  diffusionMax = std::max(diffusionMax, st.diffusion.iterations);
  unconverged += st.diffusion.converged ? 0 : 1;
}

void RDRunStats::save(StateWriter* out) const {
  out->put("rd.stats.newton", newton);
  out->put("rd.stats.diffusion_iterations", diffusionIterations);
  out->put("rd.stats.diffusion_max", diffusionMax);
  out->put("rd.stats.unconverged", unconverged);
}

void RDRunStats::load(const StateReader& in) {
  in.get("rd.stats.newton", &newton);
  in.get("rd.stats.diffusion_iterations", &diffusionIterations);
  in.get("rd.stats.diffusion_max", &diffusionMax);
  in.get("rd.stats.unconverged", &unconverged);
}

template <int D>
void CpuLayerStepper<D>::advance(double dt, long count) {
  for (long k = 0; k < count; ++k) {
    rd_->step(dt);
    stats_.add(rd_->lastStats());
  }
}

template <int D>
void CpuLayerStepper<D>::save(StateWriter* out) const {
  rd_->save(out);
  stats_.save(out);
}

template <int D>
void CpuLayerStepper<D>::load(const StateReader& in) {
  rd_->load(in);
  stats_.load(in);
}

template <int D>
void CpuLayerStepper<D>::resolved(nlohmann::json* j) const {
  (*j)["explicit_step"] = "RDSolver, double species";
}

template <int D>
std::unique_ptr<FusedLayerStepper<D>> FusedLayerStepper<D>::create(RDSolver<D>* host,
                                                                     const std::vector<int>& generalizedSpecies) {
  std::vector<double> p;
  for (size_t k = 0; k < host->model().info().parameters.size(); ++k) p.push_back(host->parameter(int(k)));
  auto fused = FusedExplicitRD<D>::create(host->model().info().name, host->cells(), host->h(),
                                          host->settings().boundary == RDBoundary::Periodic, host->diffusion(), p);
  if (!fused) return nullptr;
  if (host->generalizedDiffusion()) fused->setKernel(host->generalizedDiffusion()->kernel(), generalizedSpecies);
  return std::unique_ptr<FusedLayerStepper>(new FusedLayerStepper(host, std::move(fused)));
}

template <int D>
FusedLayerStepper<D>::FusedLayerStepper(RDSolver<D>* host, std::unique_ptr<FusedExplicitRD<D>> fused)
    : host_(host), fused_(std::move(fused)) {
  fromHost();
}

template <int D>
void FusedLayerStepper<D>::fromHost() {
  for (int s = 0; s < host_->species(); ++s) {
    const std::vector<double>& v = host_->field(s).values();
    std::vector<float>& f = fused_->field(s);
    for (size_t i = 0; i < v.size(); ++i) f[i] = float(v[i]);
  }
}

template <int D>
void FusedLayerStepper<D>::advance(double dt, long count) {
  fused_->step(dt, int(count));
  for (long k = 0; k < count; ++k) time_ += dt;  // (the same sum as step by step)
  steps_ += count;
}

template <int D>
void FusedLayerStepper<D>::toHost(RDSolver<D>* host) const {
  for (int s = 0; s < host->species(); ++s) {
    const std::vector<float>& f = fused_->field(s);
    std::vector<double>& v = host->field(s).values();
    for (size_t i = 0; i < v.size(); ++i) v[i] = double(f[i]);
  }
}

template <int D>
const RDRunStats* FusedLayerStepper<D>::runStats() const {
  static const RDRunStats none;
  return &none;
}

// (the host holds the float state: the simulation refreshes it first)
template <int D>
void FusedLayerStepper<D>::save(StateWriter* out) const {
  host_->save(out);
  RDRunStats{}.save(out);  // (the checkpoint's format is the host stepper's)
  out->put("rd.fused.time", time_);
  out->put("rd.fused.steps", steps_);
}

template <int D>
void FusedLayerStepper<D>::load(const StateReader& in) {
  host_->load(in);
  RDRunStats none;
  none.load(in);
  in.get("rd.fused.time", &time_);
  in.get("rd.fused.steps", &steps_);
  fromHost();
}

template <int D>
void FusedLayerStepper<D>::resolved(nlohmann::json* j) const {
  (*j)["explicit_step"] = "fused, float species (rd/fused_explicit.h)";
  (*j)["steps_per_pass"] = fused_->stepsPerPass();  // temporal blocking: several where the state outgrows the caches
}

template class CpuLayerStepper<2>;
template class CpuLayerStepper<3>;
template class FusedLayerStepper<2>;
template class FusedLayerStepper<3>;

}  // namespace morphoflow
