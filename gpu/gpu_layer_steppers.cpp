#include "gpu/gpu_layer_steppers.h"

#include <fmt/format.h>

#include "gpu/gl_context.h"

namespace morphoflow {

// Checkpoints: gpu.rd.time, gpu.rd.steps and the species (gpu.rd.layer.*,
// the layer's values, exact in double; gpu.rd.species.* in float), with the
// layer's warm starts.

template <int D>
void GpuLayerStepper<D>::advance(double dt, long count) {
  counts_.add([&] {
    for (long k = 0; k < count; ++k) {
      layer_.step(dt);
      stats_.add(layer_.lastStats());
    }
  });
  counts_.steps += count;
  for (long k = 0; k < count; ++k) {
    time_ += dt;
    ++steps_;
  }
}

template <int D>
void GpuLayerStepper<D>::toHost(RDSolver<D>* host) const {
  for (int s = 0; s < layer_.species(); ++s) host->field(s).values() = layer_.download(s);
}

template <int D>
void GpuLayerStepper<D>::fromHost(const RDSolver<D>& host) {
  for (int s = 0; s < layer_.species(); ++s) layer_.upload(s, host.field(s).values());
}

template <int D>
void GpuLayerStepper<D>::save(StateWriter* out) const {
  out->put("gpu.rd.time", time_);
  out->put("gpu.rd.steps", steps_);
  for (int s = 0; s < layer_.species(); ++s) out->putVector("gpu.rd.layer." + species_[size_t(s)], layer_.download(s));
  layer_.save(out);
  stats_.save(out);
}

template <int D>
void GpuLayerStepper<D>::load(const StateReader& in) {
  in.get("gpu.rd.time", &time_);
  in.get("gpu.rd.steps", &steps_);
  for (int s = 0; s < layer_.species(); ++s) {
    std::vector<double> v(layer_.cells());
    in.getVector("gpu.rd.layer." + species_[size_t(s)], &v);
    layer_.upload(s, v);
  }
  layer_.load(in);
  stats_.load(in);
}

template <int D>
void GpuLayerStepper<D>::resolved(nlohmann::json* j) const {
  (*j)["explicit_step"] = fmt::format("gpu, {} species (gpu/gpu_rd_layer.h)", precisionName(layer_.precision()));
}

template <int D>
void GpuLayerStepper<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
  (*run)["gpu"] = counts_.perStep();
  (*run)["gpu"]["precision"] = precisionName(layer_.precision());
  (*run)["gpu"]["device_bytes"] = {{"layer", layer_.deviceBytes()}, {"allocated_peak", GpuBuffer::peakBytes()}};
  (*run)["gpu"]["tolerances"] = {{"rd", layer_.tolerance()}};
}

namespace {

template <int D>
std::vector<float> floats(const Grid<double, D>& g) {
  return std::vector<float>(g.values().begin(), g.values().end());
}

}  // namespace

template <int D>
GpuExplicitLayerStepper<D>::GpuExplicitLayerStepper(const RDSolver<D>& host) : species_(host.model().info().species) {
  std::vector<double> params;
  for (size_t k = 0; k < host.model().info().parameters.size(); ++k) params.push_back(host.parameter(int(k)));
  gpu_ = std::make_unique<GpuExplicitRD>(host.settings(), host.diffusion(), params, host.model().info().clamped,
                                         floats<D>(host.field(0)), floats<D>(host.field(1)));
}

template <int D>
void GpuExplicitLayerStepper<D>::advance(double dt, long count) {
  counts_.add([&] {
    for (long k = 0; k < count; ++k) gpu_->step(dt);
  });
  counts_.steps += count;
  for (long k = 0; k < count; ++k) {
    time_ += dt;
    ++steps_;
  }
}

template <int D>
void GpuExplicitLayerStepper<D>::toHost(RDSolver<D>* host) const {
  for (int s = 0; s < 2; ++s) {
    const std::vector<float> f = gpu_->download(s);
    host->field(s).values().assign(f.begin(), f.end());
  }
}

template <int D>
void GpuExplicitLayerStepper<D>::fromHost(const RDSolver<D>& host) {
  for (int s = 0; s < 2; ++s) {
    const std::vector<double>& v = host.field(s).values();
    gpu_->upload(s, std::vector<float>(v.begin(), v.end()));
  }
}

template <int D>
void GpuExplicitLayerStepper<D>::save(StateWriter* out) const {
  out->put("gpu.rd.time", time_);
  out->put("gpu.rd.steps", steps_);
  for (int s = 0; s < 2; ++s) out->putVector("gpu.rd.species." + species_[size_t(s)], gpu_->download(s));
}

template <int D>
void GpuExplicitLayerStepper<D>::load(const StateReader& in) {
  in.get("gpu.rd.time", &time_);
  in.get("gpu.rd.steps", &steps_);
  for (int s = 0; s < 2; ++s) {
    std::vector<float> v(gpu_->cells());
    in.getVector("gpu.rd.species." + species_[size_t(s)], &v);
    gpu_->upload(s, v);
  }
}

template <int D>
void GpuExplicitLayerStepper<D>::resolved(nlohmann::json* j) const {
  (*j)["explicit_step"] = "gpu, float species (gpu/gpu_explicit_rd.h)";
}

template <int D>
void GpuExplicitLayerStepper<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
  (*run)["gpu"] = counts_.perStep();
}

template class GpuLayerStepper<2>;
template class GpuLayerStepper<3>;
template class GpuExplicitLayerStepper<2>;
template class GpuExplicitLayerStepper<3>;

}  // namespace morphoflow
