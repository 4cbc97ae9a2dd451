#include "gpu/gpu_coupled_steps.h"

#include "core/stage_trace.h"
#include "gpu/gl_context.h"

namespace morphoflow {

template <int D>
GpuCoupledSteps<D>::GpuCoupledSteps(const FluidSolver<D>& fluid, const RDSolver<D>& rd, const ChemicalDomain<D>& domain,
                                    ChemicalInterpolation interpolation, CouplingMode mode, double rdTimeScale)
    : fluid_(fluid.settings(), fluid.constraints()),
      layer_(layerUpload(rd)),
      ard_(&layer_, domain, interpolation, mode, rdTimeScale, fluid.cells(), fluid.h()) {
  fluid_.fromHost(fluid);
}

template <int D>
void GpuCoupledSteps<D>::step(double dt) {
  const double t0 = traceClock();
  ard_.step(dt, fluid_);
  fluid_.step(dt);
  // the GPU's own time of each side (timer queries, a step late)
  seconds_ = {0.0, 0.0, 0.0};
  for (double s : fluid_.lastStats().seconds) seconds_[0] += s;
  for (double s : ard_.stageSeconds()) seconds_[1] += s;
  seconds_[2] = traceClock() - t0;
}

template <int D>
void GpuCoupledSteps<D>::toHost(FluidSolver<D>* fluid, RDSolver<D>* rd) const {
  fluid_.toHost(fluid);
  for (int s = 0; s < layer_.species(); ++s) rd->field(s).values() = layer_.download(s);
}

template <int D>
void GpuCoupledSteps<D>::fromHost(const FluidSolver<D>& fluid, const RDSolver<D>& rd) {
  fluid_.fromHost(fluid);
  for (int s = 0; s < layer_.species(); ++s) layer_.upload(s, rd.field(s).values());
}

template <int D>
void GpuCoupledSteps<D>::save(StateWriter* out) const {
  fluid_.save(out);
  layer_.save(out);
}

template <int D>
void GpuCoupledSteps<D>::load(const StateReader& in) {
  fluid_.load(in);
  layer_.load(in);
}

template <int D>
void GpuCoupledSteps<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
}

template class GpuCoupledSteps<2>;
template class GpuCoupledSteps<3>;

}  // namespace morphoflow
