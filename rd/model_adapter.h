// ModelAdapter<M>: a models.h struct behind the ReactionModel interface, with
// the per-cell loops compiled against M's inline rates and Jacobian.
#pragma once

#include <algorithm>
#include <cstring>

#include "core/simd_dispatch.h"
#include "rd/newton.h"
#include "rd/newton_batch.h"
#include "rd/reaction_model.h"

namespace morphoflow {

template <class M>
class ModelAdapter final : public ReactionModel {
  static_assert(M::N <= kMaxSpecies && M::P <= kMaxParameters);

 public:
  ModelAdapter() : info_(M::info()) {
    for (int s : info_.clamped) clampMask_ |= 1u << s;
    kernel_.file = M::kKernel;
    if constexpr (requires { M::kKernelBase; }) kernel_.base = M::kKernelBase;
    if constexpr (requires { M::kKernelDefines; }) kernel_.defines = M::kKernelDefines;
  }
  const ModelInfo& info() const override { return info_; }
  const ModelKernel& kernel() const override { return kernel_; }
  void rates(const double* x, const double* p, double* r) const override { M::rates(x, p, r); }
  void jacobian(const double* x, const double* p, double* J) const override { M::jacobian(x, p, J); }

  void evaluate(const double* const* x, const ParameterValues& pv, double* const* out, size_t begin,
                size_t end) const override {
    double p[M::P], xc[M::N], r[M::N];
    const bool uniform = pv.uniform();
    if (uniform) pv.gather(0, p);
    for (size_t i = begin; i < end; ++i) {
      if (!uniform) pv.gather(i, p);
      for (int s = 0; s < M::N; ++s) xc[s] = x[s][i];
      M::rates(xc, p, r);
      for (int s = 0; s < M::N; ++s) out[s][i] = r[s];
    }
  }

  NewtonStats implicitUpdate(double* const* x, const ParameterValues& pv, double dt, size_t begin,
                             size_t end) const override {
    NewtonStats st;
    double p[M::P];
    const bool uniform = pv.uniform();
    if (uniform) pv.gather(0, p);
    size_t i = begin;
#if MORPHOFLOW_AVX2_KERNELS
    // Four cells at a time in AVX2 registers (bitwise the scalar result).
    // Compiled for SSE the same batch is slower than the scalar loop
    // (docs/performance.md), so without AVX2 every cell takes the loop below.
    if (kBatched && uniform && useAvx2()) i = updateBatchesAvx2(x, p, dt, begin, end, &st);
#endif
    for (; i < end; ++i) {
      if (!uniform) pv.gather(i, p);
      updateCell(x, p, dt, i, &st);
    }
    return st;
  }

 private:
  // The two-species models (their rates and Jacobian take vectors of doubles).
  static constexpr bool kBatched = M::N == 2 && requires(const NewtonLanes* y, const double* q, NewtonLanes* r) {
    M::rates(y, q, r);
    M::jacobian(y, q, r);
  };

  // One cell's implicit step by the scalar code.
  void updateCell(double* const* x, const double* p, double dt, size_t i, NewtonStats* st) const {
    double x0[M::N], xn[M::N];
    for (int s = 0; s < M::N; ++s) x0[s] = x[s][i];
    NewtonResult r = implicitReactionCell<M::N>(
        M::N, x0, dt, xn, [&](const double* y, double* out) { M::rates(y, p, out); },
        [&](const double* y, double* J) { M::jacobian(y, p, J); }, clampMask_);
    ++st->cells;
    st->failures += r.converged ? 0 : 1;
    st->maxIterations = std::max(st->maxIterations, r.iterations);
    st->maxResidual = std::max(st->maxResidual, r.residual);
    project(xn);
    for (int s = 0; s < M::N; ++s) x[s][i] = xn[s];
  }

#if MORPHOFLOW_AVX2_KERNELS
  // Whole groups of kNewtonLanes cells through newtonBatch (the cells it
  // hands back through updateCell); returns the first cell not done.
  __attribute__((target("avx2"))) size_t updateBatchesAvx2(double* const* x, const double* p, double dt, size_t i,
                                                           size_t end, NewtonStats* st) const {
    if constexpr (kBatched) {
      for (; i + kNewtonLanes <= end; i += kNewtonLanes) {
        NewtonLanes x0[2], xn[2];
        for (int s = 0; s < 2; ++s) std::memcpy(&x0[s], x[s] + i, sizeof(NewtonLanes));
        NewtonBatch b;
        newtonBatch<M>(x0, p, dt, clampMask_, kNewtonMaxIterations, xn, &b);
        for (int s = 0; s < 2; ++s) std::memcpy(x[s] + i, &xn[s], sizeof(NewtonLanes));
        for (int l = 0; l < kNewtonLanes; ++l) {
          if ((b.scalar >> l) & 1u) {  // its x is still x0
            updateCell(x, p, dt, i + size_t(l), st);
            continue;
          }
          ++st->cells;
          st->maxIterations = std::max(st->maxIterations, b.iterations[l]);
          st->maxResidual = std::max(st->maxResidual, b.residual[l]);
        }
      }
    }
    return i;
  }
#endif

  ModelInfo info_;
  ModelKernel kernel_;
  unsigned clampMask_ = 0;
};

}  // namespace morphoflow
