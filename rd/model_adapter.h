// ModelAdapter<M>: a models.h struct behind the ReactionModel interface, with
// the per-cell loops compiled against M's inline rates and Jacobian.
#pragma once

#include "rd/newton.h"
#include "rd/reaction_model.h"

namespace morphoflow {

template <class M>
class ModelAdapter final : public ReactionModel {
  static_assert(M::N <= kMaxSpecies && M::P <= kMaxParameters);

 public:
  ModelAdapter() : info_(M::info()) {
    for (int s : info_.clamped) clampMask_ |= 1u << s;
  }
  const ModelInfo& info() const override { return info_; }
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
    double p[M::P], x0[M::N], xn[M::N];
    const bool uniform = pv.uniform();
    if (uniform) pv.gather(0, p);
    for (size_t i = begin; i < end; ++i) {
      if (!uniform) pv.gather(i, p);
      for (int s = 0; s < M::N; ++s) x0[s] = x[s][i];
      NewtonResult r = implicitReactionCell<M::N>(
          M::N, x0, dt, xn, [&](const double* y, double* out) { M::rates(y, p, out); },
          [&](const double* y, double* J) { M::jacobian(y, p, J); }, clampMask_);
      ++st.cells;
      st.failures += r.converged ? 0 : 1;
      st.maxIterations = std::max(st.maxIterations, r.iterations);
      st.maxResidual = std::max(st.maxResidual, r.residual);
      project(xn);
      for (int s = 0; s < M::N; ++s) x[s][i] = xn[s];
    }
    return st;
  }

 private:
  ModelInfo info_;
  unsigned clampMask_ = 0;
};

}  // namespace morphoflow
