#include "gpu/gpu_coupled_stepper.h"

#include <cstring>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "core/stage_trace.h"
#include "coupling/solid_on_layer.h"
#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

template <int D>
GpuCoupledStepper<D>::GpuCoupledStepper(const FluidSolver<D>& fluid, const RDSolver<D>& rd,
                                        const ChemicalDomain<D>& domain, ChemicalInterpolation interpolation,
                                        CouplingMode mode, double rdTimeScale, GpuPrecision real)
    : fluid_(fluid.settings(), fluid.constraints(), real),
      layer_(layerUpload(rd), real),
      ard_(&layer_, domain, interpolation, mode, rdTimeScale, fluid.cells(), fluid.h()),
      none_(sizeof(int)),
      rdH_(rd.h()) {
  fluid_.fromHost(fluid);
  for (int a = 0; a < D; ++a) {
    rdCells_[size_t(a)] = rd.cells()[a];
    fluidCells_[size_t(a)] = fluid.cells()[a];
  }
}

template <int D>
void GpuCoupledStepper<D>::step(double dt) {
  const double t0 = traceClock();
  counts_.add([&] {
    if (fluid_.movesObstacles()) moveSolids(dt);
    fluid_.step(dt);
    ard_.step(dt, fluid_);
  });
  ++counts_.steps;
  // the GPU's own time of each side (timer queries, a step late)
  seconds_ = {0.0, 0.0, 0.0};
  for (double s : fluid_.lastStats().seconds) seconds_[0] += s;
  for (double s : ard_.stageSeconds()) seconds_[1] += s;
  seconds_[2] = traceClock() - t0;
}

// A moving obstacle: the fluid's solid where this step ends, and the
// chemicals' solid cells with it (as CpuCoupledStepper::moveSolids).
template <int D>
void GpuCoupledStepper<D>::moveSolids(double dt) {
  IVec<D> rdCells;
  for (int a = 0; a < D; ++a) rdCells[a] = rdCells_[size_t(a)];
  const Grid<uint8_t, D> was = solidOnLayer<D>(fluid_.movingSolid(), fluid_.h(), rdCells, rdH_);
  fluid_.placeObstaclesFor(dt);
  ard_.moveSolid(was, solidOnLayer<D>(fluid_.movingSolid(), fluid_.h(), rdCells, rdH_));
}

template <int D>
void GpuCoupledStepper<D>::toHost(FluidSolver<D>* fluid, RDSolver<D>* rd) const {
  fluid_.toHost(fluid);
  for (int s = 0; s < layer_.species(); ++s) rd->field(s).values() = layer_.download(s);
}

template <int D>
void GpuCoupledStepper<D>::fromHost(const FluidSolver<D>& fluid, const RDSolver<D>& rd) {
  fluid_.fromHost(fluid);
  for (int s = 0; s < layer_.species(); ++s) layer_.upload(s, rd.field(s).values());
}

template <int D>
void GpuCoupledStepper<D>::save(StateWriter* out) const {
  fluid_.save(out);
  layer_.save(out);
}

template <int D>
void GpuCoupledStepper<D>::load(const StateReader& in) {
  fluid_.load(in);
  layer_.load(in);
}

template <int D>
void GpuCoupledStepper<D>::report(nlohmann::json* run) const {
  recordGlContext(run);
  nlohmann::json g = counts_.perStep();
  g["stages"] = fluid_.stageTimer().countsPerStep(FluidStepStats::kStageNames);
  g["stages"].update(ard_.stageTimer().countsPerStep(ARDSolver<D>::kStageNames));
  g["precision"] = precisionName(layer_.precision());
  g["device_bytes"] = {
      {"fluid", fluid_.deviceBytes()}, {"layer", layer_.deviceBytes()}, {"allocated_peak", GpuBuffer::peakBytes()}};
  g["tolerances"] = fluid_.tolerances();
  g["tolerances"]["rd"] = layer_.tolerance();
  (*run)["gpu"] = g;
}

// shaders/smoke_layer.comp over every layer cell, all species.
template <int D>
void GpuCoupledStepper<D>::layerKernel(bool blend, const GpuBuffer& cover, const std::vector<double>& values,
                                     double threshold) {
  const int ns = layer_.species();
  const ComputeProgram& p = useProgram(
      "smoke_layer.comp",
      fmt::format("#define DIM {}\n#define NSPECIES {}\n#define {}", D, ns, blend ? "MODE_BLEND" : "MODE_MASK"),
      layer_.precision());
  setUniform(p, "n", int(layer_.cells()));
  setUniform(p, "rdCells", rdCells_);
  setUniform(p, "cells", fluidCells_);
  setUniform(p, "tapOff", tapOff_);
  setUniformDoubles(p, "values", values.data(), ns);
  setUniform(p, "threshold", threshold);
  for (int s = 0; s < ns; ++s) layer_.field(s).bind(s);
  cover.bind(8);
  fluid_.dye().bind(9);
  (taps_.bytes() ? taps_ : none_).bind(10);
  dispatchFlat(layer_.cells(), 2.0 * double(realBytes(layer_.precision())) * ns + 4.0 * (blend ? 1 : 1 << D));
  storageBarrier();
}

template <int D>
void GpuCoupledStepper<D>::blendLayer(int id, const Grid<float, D>& cover, const std::vector<double>& values) {
  auto it = covers_.find(id);
  if (it == covers_.end())
    it = covers_.emplace(id, GpuBuffer::of(cover.values())).first;
  else if (id < 0)
    it->second.upload(cover.values());
  counts_.add([&] { layerKernel(true, it->second, values, 0.0); });
}

template <int D>
void GpuCoupledStepper<D>::maskLayer(const SmokeTaps<D>& taps, double threshold, const std::vector<double>& rest) {
  if (taps_.bytes() == 0) {
    std::vector<int> flat;
    for (int a = 0; a < D; ++a) {
      tapOff_[size_t(a)] = int(flat.size());
      for (size_t k = 0; k < taps.t[a].size(); ++k) {
        int bits;
        std::memcpy(&bits, &taps.t[a][k], sizeof bits);
        flat.insert(flat.end(), {taps.i0[a][k], taps.i1[a][k], bits});
      }
    }
    taps_ = GpuBuffer::of(flat);
  }
  counts_.add([&] { layerKernel(false, none_, rest, threshold); });
}

template class GpuCoupledStepper<2>;
template class GpuCoupledStepper<3>;

}  // namespace morphoflow
