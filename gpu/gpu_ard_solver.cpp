#include "gpu/gpu_ard_solver.h"

#include <cmath>
#include <stdexcept>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "coupling/ard_step.h"
#include "gpu/compute_program.h"
#include "gpu/fluid/gpu_fill.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"
#include "gpu/gpu_stage_timer.h"

namespace morphoflow {

template <int D>
GpuARDSolver<D>::GpuARDSolver(GpuRDLayer<D>* layer, const ChemicalDomain<D>& domain,
                              ChemicalInterpolation interpolation, CouplingMode mode, double rdTimeScale,
                              const IVec<D>& fluidCells, double fluidH)
    : layer_(layer),
      domain_(domain),
      cubic_(interpolation == ChemicalInterpolation::Cubic),
      spline_(interpolation == ChemicalInterpolation::BSpline),
      bfecc_(interpolation == ChemicalInterpolation::BFECC),
      mode_(mode),
      rdTimeScale_(rdTimeScale),
      fluidH_(fluidH) {
  if (!(rdTimeScale > 0)) throw std::invalid_argument("coupling: the reaction-diffusion time scale must be > 0");
  for (int a = 0; a < D; ++a) {
    fluidCells_[size_t(a)] = fluidCells[a];
    rdCells_[size_t(a)] = domain.cells[a];
    periodic_[size_t(a)] = domain.periodic[size_t(a)] ? 1 : 0;
  }
  hasSolids_ = !domain.solid.empty();
  solid_ = GpuBuffer::of(hasSolids_ ? std::vector<uint32_t>(domain.solid.begin(), domain.solid.end())
                                    : std::vector<uint32_t>{0});
  for (GpuBuffer& b : scratch_) b = realBuffer(layer->cells(), layer->precision());
  for (GpuBuffer& b : coefficients_) b = realBuffer(spline_ || bfecc_ ? layer->cells() : 1, layer->precision());
  if (mode_ != CouplingMode::RDOnly) emptySolids();
  timer_ = std::make_unique<GpuStageTimer>(ARDSolver<D>::kStages);
}

template <int D>
void GpuARDSolver<D>::emptySolids() {
  if (!hasSolids_) return;
  const ComputeProgram& p =
      useProgram("chem_advect.comp", fmt::format("#define DIM {}\n#define MODE_SOLIDS", D), layer_->precision());
  setUniform(p, "rdCells", rdCells_);
  auto value = [&](size_t s) { return s < domain_.solidValues.size() ? domain_.solidValues[s] : 0.0; };
  const std::array<double, 2> solid{value(0), value(1)};
  setUniformDoubles(p, "solidValue", solid.data(), 1, 2);
  layer_->field(0).bind(3);
  layer_->field(1).bind(4);
  solid_.bind(5);
  dispatchFlat(layer_->cells(), 4.0 + 2.0 * double(realBytes(layer_->precision())));  // the mask, both species written
  storageBarrier();
}

template <int D>
void GpuARDSolver<D>::moveSolid(const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now) {
  const GpuFill fill(fillPlan<D>(was, now));
  for (int s = 0; s < 2; ++s)
    fill.apply(layer_->field(s), 0, layer_->precision(),
               size_t(s) < domain_.solidValues.size() ? domain_.solidValues[size_t(s)] : 0.0);
  domain_.solid.assign(now.values().begin(), now.values().end());
  const std::vector<uint32_t> flags(now.values().begin(), now.values().end());
  if (solid_.bytes() == flags.size() * sizeof(uint32_t)) solid_.upload(flags);
  else solid_ = GpuBuffer::of(flags);
  hasSolids_ = true;
}

// Each species' B-spline coefficients (coupling/bspline.h): a copy, then
// one pass a line along each axis (shaders/chem_advect.comp MODE_PREFILTER).
template <int D>
void GpuARDSolver<D>::prefilter() {
  const double z = std::sqrt(3.0) - 2.0;
  for (int s = 0; s < 2; ++s) {
    coefficients_[size_t(s)].copyFrom(layer_->field(s), layer_->cells() * realBytes(layer_->precision()));
    for (int a = 0; a < D; ++a) {
      const int n = rdCells_[size_t(a)];
      const ComputeProgram& p =
          useProgram("chem_advect.comp", fmt::format("#define DIM {}\n#define MODE_PREFILTER", D), layer_->precision());
      setUniform(p, "rdCells", rdCells_);
      setUniform(p, "periodic", periodic_);
      setUniform(p, "axis", a);
      const int lines = int(layer_->cells() / size_t(n));
      setUniform(p, "lines", lines);
      setUniform(p, "z", z);
      setUniform(p, "zn", std::pow(z, n));
      setUniform(p, "z2n", std::pow(z, 2 * n - 2));
      coefficients_[size_t(s)].bind(3);
      dispatchFlat(size_t(lines),
                   4.0 * double(realBytes(layer_->precision())) * n);  // each line read and written twice
      storageBarrier();
    }
  }
}

// One pass of chem_advect.comp's MODE_ADVECT over dt: from `from` into
// `into`, with the interpolation's choices and `correct` for BFECC's last pass
// (reading the backward step from coefficients_).
template <int D>
void GpuARDSolver<D>::advectPass(double dt, const GpuFluid<D>& fluid, Pair from, Pair into, bool correct) {
  const ComputeProgram& p =
      useProgram("chem_advect.comp", fmt::format("#define DIM {}\n#define MODE_ADVECT", D), layer_->precision());
  setUniform(p, "cells", fluidCells_);
  setUniform(p, "periodic", periodic_);
  setUniform(p, "velOff",
             std::array<int, 3>{int(fluid.offset(0)), int(fluid.offset(1)), D == 3 ? int(fluid.offset(2)) : 0});
  setUniform(p, "rdCells", rdCells_);
  setUniform(p, "c", float(dt / fluidH_));
  setUniform(p, "r", float(domain_.h / fluidH_));
  std::array<int, 3> lo{}, hi{};
  for (int a = 0; a < D; ++a) {
    lo[size_t(a)] = domain_.inflow[size_t(a)][0] ? 1 : 0;
    hi[size_t(a)] = domain_.inflow[size_t(a)][1] ? 1 : 0;
  }
  setUniform(p, "inflowLo", lo);
  setUniform(p, "inflowHi", hi);
  const bool inflow = !domain_.inflowValues.empty();
  setUniform(p, "inflow", inflow ? 1 : 0);
  auto in = [&](size_t s) { return inflow && s < domain_.inflowValues.size() ? domain_.inflowValues[s] : 0.0; };
  const std::array<double, 2> inValue{in(0), in(1)};
  setUniformDoubles(p, "inValue", inValue.data(), 1, 2);
  setUniform(p, "cubic", cubic_ ? 1 : 0);
  setUniform(p, "spline", spline_ ? 1 : 0);
  setUniform(p, "bfecc", correct ? 1 : 0);
  coefficients_[0].bind(6);
  coefficients_[1].bind(7);
  fluid.advectedVelocity().bind(0);
  from[0]->bind(1);
  from[1]->bind(2);
  into[0]->bind(3);
  into[1]->bind(4);
  solid_.bind(5);
  // both species read and written, the velocity once (the fluid's grid, here per chemical cell at most)
  dispatchFlat(layer_->cells(), (correct ? 6 : 4) * double(realBytes(layer_->precision())) + 4.0 * D);
  storageBarrier();
}

template <int D>
void GpuARDSolver<D>::advect(double dt, const GpuFluid<D>& fluid) {
  if (spline_) prefilter();
  const Pair species{&layer_->field(0), &layer_->field(1)}, scratch{&scratch_[0], &scratch_[1]};
  if (bfecc_) {
    // BFECC (chemical_advection.cpp): forward into scratch_, backward into
    // coefficients_, then the compensated forward step into scratch_.
    bfeccPasses([&] { advectPass(dt, fluid, species, scratch, false); },
                [&] {
                  advectPass(-dt, fluid, scratch, {&coefficients_[0], &coefficients_[1]}, false);
                },
                [&] { advectPass(dt, fluid, species, scratch, true); });
  } else {
    advectPass(dt, fluid, species, scratch, false);
  }
  for (int s = 0; s < 2; ++s) std::swap(layer_->field(s), scratch_[size_t(s)]);
  emptySolids();
}

template <int D>
void GpuARDSolver<D>::step(double dt, const GpuFluid<D>& fluid) {
  // The GPU's stages of the ARD step, whose order is coupling/ard_step.h's.
  struct Stages {
    GpuARDSolver& s;
    const GpuFluid<D>& fluid;
    void reactDiffuse(double t) { s.layer_->step(t); }
    void emptySolids() { s.emptySolids(); }
    void advect(double t) { s.advect(t, fluid); }
  } stages{*this, fluid};
  timer_->mark(0);
  reactDiffuseChemicals(stages, mode_, rdTimeScale_, dt);
  timer_->mark(1);
  advectChemicals(stages, mode_, dt);
  timer_->mark(2);
  const std::vector<double> seconds = timer_->endStep();
  stageSeconds_ = {seconds[0], seconds[1]};
}

template class GpuARDSolver<2>;
template class GpuARDSolver<3>;

}  // namespace morphoflow
