#include "gpu/fluid/gpu_advection.h"

#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

template <int D>
GpuAdvection<D>::GpuAdvection(const GpuMacGrid<D>& grid, AdvectionScheme scheme, GpuPrecision real)
    : grid_(grid), scheme_(scheme), real_(real) {
  for (GpuBuffer* b : {&lo_, &hi_, &back_, &fwd_}) *b = GpuBuffer(grid_.maxGrid * sizeof(float));
}

template <int D>
void GpuAdvection<D>::advect(const GpuBuffer& src, size_t srcOff, const std::array<int, 3>& dims,
                             const std::array<float, 3>& offset, double dt, GpuBuffer* dst, size_t dstOff) {
  const size_t n = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
  auto pass = [&](const GpuBuffer& in, size_t inOff, double step, GpuBuffer* out, size_t outOff, bool limits) {
    const ComputeProgram& p =
        useProgram("advect.comp", fmt::format("#define DIM {}{}", D, limits ? "\n#define LIMITS" : ""));
    setUniform(p, "cells", grid_.cells);
    setUniform(p, "periodic", grid_.periodic);
    setUniform(p, "velOff", grid_.velocityOffsets());
    setUniform(p, "c", float(step / grid_.h));
    setUniform(p, "sdims", dims);
    setUniform(p, "soff", offset);
    setUniform(p, "srcOff", int(inOff));
    setUniform(p, "dstOff", int(outOff));
    grid_.vel.bind(0);
    in.bind(1);
    out->bind(2);
    lo_.bind(3);
    hi_.bind(4);
    dispatchFlat(n, 8.0 + 4.0 * D + (limits ? 8.0 : 0.0));  // src, dst, the velocity once (, lo, hi)
    storageBarrier();
  };
  auto combine = [&](FluidOp mode, const GpuBuffer& f0, size_t f0Off, const GpuBuffer& f1, size_t f1Off,
                     const GpuBuffer& f2, const GpuBuffer& f3, const GpuBuffer& f4) {
    const ComputeProgram& p = grid_.stage(mode, real_);
    setUniform(p, "n", int(n));
    setUniform(p, "dstOff", int(f0Off));
    setUniform(p, "f1Off", int(f1Off));
    f0.bind(3);
    f1.bind(4);
    f2.bind(5);
    f3.bind(6);
    f4.bind(11);
    dispatchFlat(n, mode == FluidOp::MacCormack ? 24.0 : mode == FluidOp::BfeccCorrect ? 12.0 : 16.0);
    storageBarrier();
  };
  switch (scheme_) {
    case AdvectionScheme::SemiLagrangian:
      pass(src, srcOff, dt, dst, dstOff, false);
      break;
    case AdvectionScheme::MacCormack:
      // phi^ = A(phi); phi~ = A^-1(phi^); phi = phi^ + (phi - phi~) / 2, limited
      pass(src, srcOff, dt, dst, dstOff, true);
      pass(*dst, dstOff, -dt, &back_, 0, false);
      combine(FluidOp::MacCormack, *dst, dstOff, src, srcOff, back_, lo_, hi_);
      break;
    case AdvectionScheme::Bfecc:
      // phi_bar = phi + (phi - A^-1 A phi) / 2, then A(phi_bar), limited
      pass(src, srcOff, dt, &fwd_, 0, false);
      pass(fwd_, 0, -dt, &back_, 0, false);
      combine(FluidOp::BfeccCorrect, fwd_, 0, src, srcOff, back_, back_, back_);
      pass(fwd_, 0, dt, dst, dstOff, false);
      pass(src, srcOff, dt, &back_, 0, true);  // the first-order fallback
      combine(FluidOp::BfeccLimit, *dst, dstOff, back_, 0, lo_, hi_, hi_);
      break;
  }
}

template class GpuAdvection<2>;
template class GpuAdvection<3>;

}  // namespace morphoflow
