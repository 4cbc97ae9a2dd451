// Chebyshev iteration (Golub & Varga 1961; Saad, "Iterative Methods for
// Sparse Linear Systems", 2nd ed., sec. 12.3) for a LaplaceSystem with an
// identity term: the systems (I - nu dt lap) of implicit viscosity and
// diffusion. Scaled by its diagonal, such a system is I - D^-1 W, and
// Gershgorin bounds its spectrum to [1 - rho, 1 + rho] with
// rho = max_i (sum_f w_f) / diag_i < 1. The iteration is optimal for that
// interval (its residual polynomial is the scaled Chebyshev polynomial,
// |p_k| <= 1 / T_k(1 / rho) there), so the number of steps a reduction
// needs is known in advance and no step takes an inner product. A step is a
// Jacobi-like sweep, e_k = w_k (e_{k-1} - e_{k-2} + (g - M e_{k-1}) / theta) + e_{k-2},
// whose writes go to the e_{k-2} vector in place.
//
// The steps run on the correction, in single precision, inside a double
// precision outer loop (r = b - A x; x += e; mixed-precision refinement).
// They are blocked in time: one pass over memory advances several steps,
// plane by plane along the last axis (step t on plane p - t + 1 right after
// step t - 1 on plane p), so the planes in flight stay in cache. Planes are
// cut into slabs, one task each, whose steps shrink away from the slab's
// edges; a second, short loop then fills the triangles around each cut.
// Every step of every plane reads the same values however the planes are
// cut and ordered: the result is bitwise independent of the thread count.
#pragma once

#include <vector>

#include "core/laplace_system.h"
#include "core/pcg.h"
#include "core/solver_result.h"

namespace morphoflow {

// How the steps are laid out over memory and tasks: any choice gives
// bitwise the same result (tests compare them), only the speed differs.
struct ChebyshevLayout {
  int stepsPerPass = 4;  // steps per pass over memory; 1: plain sweeps
  int slabs = 0;         // tasks per pass (at most); 0: one per thread
};

template <int D>
class Chebyshev {
 public:
  explicit Chebyshev(const LaplaceSystem<D>& A, const ChebyshevLayout& layout = {});

  // The system's coefficients changed, not its shape: bound the spectrum again.
  void refresh();
  // False where no identity term bounds rho below 1 (a pure Laplacian).
  bool applicable() const { return rho_ < 1.0; }
  // The Gershgorin radius rho of D^-1 W.
  double rho() const { return rho_; }
  // Steps that reduce the residual's 2-norm by `factor` in exact arithmetic:
  // the least k with T_k(1 / rho) >= factor sqrt(max diag / min diag).
  int stepsFor(double factor) const;

  // Solves A x = b from *x to the relative residual options.tolerance;
  // iterations counts the Chebyshev steps (plain CG where not applicable).
  SolverResult solve(const Vector& b, Vector* x, const SolverOptions& options);

 private:
  // e = `steps` Chebyshev steps from 0 on M e = g, g = rscale D^-1 r / scale.
  void run(int steps, const Vector& r, double rscale);
  // Step `level` (>= 1; the first forms g) on plane q along the last axis.
  void plane(int level, size_t q, const Vector& r, double rscale);

  const LaplaceSystem<D>& A_;
  ChebyshevLayout layout_;
  double rho_ = 1.0;
  double diagRatio_ = 1.0;    // max / min diagonal over active cells
  std::vector<float> e_[2];   // step k lives in e_[k & 1]
  std::vector<float> g_;      // D^-1 r, scaled
  std::vector<float> zeros_;  // a row of zeros: beyond a non-periodic edge
  std::vector<float> omega_;  // omega_[k] of step k
  Vector r_;
};

}  // namespace morphoflow
