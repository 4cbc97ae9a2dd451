// Kim & Lin's implicit reaction step (seed 001 eq. 6) for four cells at
// once: rd/newton.h's Newton iteration, x - x0 - dt R(x) = 0, run in the
// lanes of a vector of doubles, lane by lane in lockstep, for a two-species
// model whose rates and Jacobian take vectors (rd/models.h).
//
// Every lane does newtonFrom's arithmetic in its order and without FMA, so a
// lane that converges taking full Newton steps ends bitwise where the scalar
// code ends. Any other lane (a step the line search would shorten, a
// singular Jacobian, a NaN, no convergence in the iteration limit, a clamped
// species below 0) is reported back, and its cell goes through the scalar
// code from its start: the batch decides nothing the scalar code would not,
// it only does the common case four cells at a time.
#pragma once

#include <cstddef>

namespace morphoflow {

typedef double NewtonLanes __attribute__((vector_size(32)));
typedef long long NewtonMask __attribute__((vector_size(32)));
constexpr int kNewtonLanes = 4;

struct NewtonBatch {
  unsigned scalar = 0;             // lanes the scalar code must redo (bit per lane)
  int iterations[kNewtonLanes]{};  // per lane (meaningful where not scalar)
  double residual[kNewtonLanes]{}; // max |F| at the returned x
};

namespace newton_batch_detail {
// |v| (std::abs: the sign bit cleared).
[[gnu::always_inline]] inline void absInto(const NewtonLanes& v, NewtonLanes* out) {
  *out = (NewtonLanes)((NewtonMask)v & 0x7fffffffffffffffll);
}
// F = y - x0 - dt R(y), m = max_s |F_s| (std::max's order), q = sum F_s^2.
template <class M>
[[gnu::always_inline]] inline void residual(const NewtonLanes (&y)[2], const NewtonLanes (&x0)[2], const double* p,
                                            double dt, NewtonLanes (&F)[2], NewtonLanes* m, NewtonLanes* q) {
  NewtonLanes r[2];
  M::rates(y, p, r);
  NewtonLanes mm{}, qq{};
  for (int s = 0; s < 2; ++s) {
    F[s] = y[s] - x0[s] - dt * r[s];
    NewtonLanes a;
    absInto(F[s], &a);
    mm = mm < a ? a : mm;
    qq += F[s] * F[s];
  }
  *m = mm;
  *q = qq;
}
}  // namespace newton_batch_detail

// x <- the root of x - x0 - dt R(x) = 0 for the four cells in x0's lanes,
// started from x0 (newtonImplicit's first attempt); lanes handed back to
// the scalar code keep x0. `clamped` marks species
// that must end >= 0 (implicitReactionCell's rule); `maxIterations` as
// newtonFrom's.
template <class M>
[[gnu::always_inline]] inline void newtonBatch(const NewtonLanes (&x0)[2], const double* p, double dt,
                                               unsigned clamped, int maxIterations, NewtonLanes (&x)[2],
                                               NewtonBatch* out) {
  using namespace newton_batch_detail;
  static_assert(M::N == 2);
  NewtonLanes scale = NewtonLanes{} + 1.0;
  for (int s = 0; s < 2; ++s) {
    x[s] = x0[s];
    NewtonLanes a;
    absInto(x0[s], &a);
    scale = scale < a ? a : scale;  // max(scale, |x0_s|, |x_s|) with x = x0
  }
  NewtonLanes F[2], fnorm, q;
  residual<M>(x, x0, p, dt, F, &fnorm, &q);
  NewtonMask active = NewtonMask{} - 1, scalar{}, iterations{};
  NewtonLanes J[4] = {};  // the model sets it; zeroed, or GCC 12 warns it may be used unset
  for (int it = 0;; ++it) {
    const NewtonLanes tol = 1e-12 * scale;
    const NewtonMask more = fnorm > tol;  // false on NaN, as the scalar test
    scalar |= active & ~more & ~(fnorm <= tol);  // stopped unconverged (NaN)
    active &= more;
    if (it >= maxIterations) scalar |= active, active = NewtonMask{};
    bool any = false;
    for (int l = 0; l < kNewtonLanes; ++l) any |= active[l] != 0;
    if (!any) break;
    iterations -= active;
    M::jacobian(x, p, J);
    // solveDense<2> on A = I - dt J, b = -F: the same pivot and operations.
    NewtonLanes a00 = 1.0 - dt * J[0], a01 = 0.0 - dt * J[1], a10 = 0.0 - dt * J[2], a11 = 1.0 - dt * J[3];
    NewtonLanes b0 = -F[0], b1 = -F[1];
    NewtonLanes abs00, abs10;
    absInto(a00, &abs00);
    absInto(a10, &abs10);
    const NewtonMask swap = abs10 > abs00;
    const NewtonLanes t00 = swap ? a10 : a00, t01 = swap ? a11 : a01, t10 = swap ? a00 : a10,
                      t11 = swap ? a01 : a11, c0 = swap ? b1 : b0, c1 = swap ? b0 : b1;
    a00 = t00, a01 = t01, a10 = t10, a11 = t11, b0 = c0, b1 = c1;
    absInto(a00, &abs00);
    NewtonMask singular = ~(abs00 > 1e-300);
    const NewtonLanes f = a10 / a00;
    a11 -= f * a01;
    b1 -= f * b0;
    NewtonLanes abs11;
    absInto(a11, &abs11);
    singular |= ~(abs11 > 1e-300);
    b1 = b1 / a11;
    b0 = (b0 - a01 * b1) / a00;
    scalar |= active & singular;  // the scalar code takes a fixed-point step
    active &= ~singular;
    // The line search's first try, lambda = 1 (x + 1 d = x + d exactly).
    NewtonLanes xn[2] = {x[0] + b0, x[1] + b1}, Fn[2], fn, qn;
    residual<M>(xn, x0, p, dt, Fn, &fn, &qn);
    const NewtonMask accepted = qn <= (1.0 - 2e-4 * 1.0) * q;
    scalar |= active & ~accepted;  // the scalar code would shorten the step
    active &= accepted;
    for (int s = 0; s < 2; ++s) {
      x[s] = active ? xn[s] : x[s];
      F[s] = active ? Fn[s] : F[s];
      NewtonLanes a;
      absInto(x[s], &a);
      scale = active & (scale < a) ? a : scale;
    }
    fnorm = active ? fn : fnorm;
    q = active ? qn : q;
  }
  for (int s = 0; s < 2; ++s)
    if ((clamped >> s) & 1u) scalar |= x[s] < 0.0;
  for (int s = 0; s < 2; ++s) x[s] = scalar ? x0[s] : x[s];  // the scalar code starts those cells over
  out->scalar = 0;
  for (int l = 0; l < kNewtonLanes; ++l) {
    if (scalar[l]) out->scalar |= 1u << l;
    out->iterations[l] = int(iterations[l]);
    out->residual[l] = fnorm[l];
  }
}

}  // namespace morphoflow
