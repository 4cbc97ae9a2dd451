// Newton-Raphson for one cell's implicit reaction step (Kim & Lin sec. 3.2,
// eq. 6):  F(x) = x - x0 - dt R(x) = 0,  J_F = I - dt dR/dx, with a
// backtracking line search on |F| so it cannot run away on the stiff cubic
// kinetics (FitzHugh-Nagumo, Barkley) at large dt. The steps are written once,
// in kernels/newton.inc, for the CPU (included here into NewtonKernel) and
// the GPU (gpu/shaders/rd_react.comp embeds the same file).
#pragma once

#include <algorithm>
#include <cmath>

namespace morphoflow {

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  // max |F| at the returned x
};

// The C++ side of the kernels' dialect for kernels/newton.inc.
#define ARRAY_IN(name) const double* name
#define ARRAY_OUT(name) double* name
#define ARRAY_INOUT(name) double* name
#define MATRIX_INOUT(name) double (&name)[N][N]
#define OUT(type, name) type& name
#define PRECISE
#define LIT(v) v
#define CONSTEXPR static constexpr
#define NS n
#define NT double
#define NEWTON_TOLERANCE 1e-12
#define NEWTON_TINY 1e-300

// One cell's solver: n species (at most N), the model's rates(y, r) and jacobian(y, J).
template <int N, typename Rates, typename Jacobian>
struct NewtonKernel {
  using uint = unsigned;
  int n;
  Rates& rates_;
  Jacobian& jacobian_;

  void rates(const double* y, double* r) const { rates_(y, r); }
  void jacobian(const double* y, double* J) const { jacobian_(y, J); }
  static double abs(double v) { return std::abs(v); }
  static double max(double a, double b) { return std::max(a, b); }
  static double ldexp(double v, int e) { return std::ldexp(v, e); }

#include "kernels/newton.inc"
};

#undef ARRAY_IN
#undef ARRAY_OUT
#undef ARRAY_INOUT
#undef MATRIX_INOUT
#undef OUT
#undef PRECISE
#undef LIT
#undef CONSTEXPR
#undef NS
#undef NT
#undef NEWTON_TOLERANCE
#undef NEWTON_TINY

// Newton iterations per attempt (each start or continuation stage), kernels/newton.inc's.
inline constexpr int kNewtonMaxIterations = NewtonKernel<1, int, int>::newtonMaxIterations();

// Newton from x (the species whose bit is set in `fixed` keep their value).
template <int N, typename Rates, typename Jacobian>
NewtonResult newtonFrom(int n, const double* x0, double dt, double* x, Rates&& rates, Jacobian&& jacobian,
                        unsigned fixed, int maxIterations) {
  return NewtonKernel<N, Rates, Jacobian>{n, rates, jacobian}.newtonFrom(x0, dt, x, fixed, maxIterations);
}

// Newton from x0, continuation in dt and restarts where it stagnates.
template <int N, typename Rates, typename Jacobian>
NewtonResult newtonImplicit(int n, const double* x0, double dt, double* x, Rates&& rates, Jacobian&& jacobian,
                            unsigned fixed = 0) {
  return NewtonKernel<N, Rates, Jacobian>{n, rates, jacobian}.newtonImplicit(x0, dt, x, fixed);
}

// The implicit reaction step with the species in `clamped` (a bit mask) >= 0:
// the complementarity solution of x = x0 + dt R(x), x_c >= 0.
template <int N, typename Rates, typename Jacobian>
NewtonResult implicitReactionCell(int n, const double* x0, double dt, double* x, Rates&& rates, Jacobian&& jacobian,
                                  unsigned clamped) {
  return NewtonKernel<N, Rates, Jacobian>{n, rates, jacobian}.implicitReaction(x0, dt, x, clamped);
}

}  // namespace morphoflow
