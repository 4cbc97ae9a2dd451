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
// Where the grid is two-coloured like a chessboard (the stencil couples a
// cell to the other colour only; every periodic axis has an even length),
// the steps take the colours in turn (Golub & Varga's cyclic Chebyshev
// semi-iteration): step k updates only the cells of colour k mod 2, whose
// e_k reads the other colour's e_{k-1} and its own e_{k-2}, so the cells
// of the other colour's e_k are never needed. Each colour is stored apart,
// contiguous along x, so a step is half a sweep; the values are the full
// iteration's, bitwise. A round of k steps ends with a plain Jacobi half
// step that takes the colour left at e_{k-1} from the other's e_k, which
// zeroes its residual: the rest is the reduced (Schur complement) system's,
// on which the even steps are the optimal Chebyshev polynomial in (D^-1 W)^2.
// About k / 2 sweeps' work for a residual within about 1.25 of the full
// iteration's after k steps (a round asks for a little more reduction).
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
  bool cyclic = true;    // the colours in turn where the grid has two (false: every cell every step)
};

// The iteration's work vectors (single precision). Solvers that run one
// after another may share one (the viscosity's components do).
struct ChebyshevWork {
  std::vector<float> e[2];  // step k lives in e[k & 1] (cyclic: colour k & 1's cells)
  std::vector<float> g;     // D^-1 r, scaled (cyclic: colour 0's cells, then colour 1's)
};

template <int D>
class Chebyshev {
 public:
  // work: shared work vectors (null: its own).
  explicit Chebyshev(const LaplaceSystem<D>& A, const ChebyshevLayout& layout = {}, ChebyshevWork* work = nullptr);

  // The system's coefficients changed, not its shape: bound the spectrum again.
  void refresh();
  // False where no identity term bounds rho below 1 (a pure Laplacian).
  bool applicable() const { return rho_ < 1.0; }
  // The Gershgorin radius rho of D^-1 W.
  double rho() const { return rho_; }
  // Whether the steps take the colours in turn (see above), and the cells
  // a step updates: half the system's where they do.
  bool cyclic() const { return cyclic_; }
  double cellsPerStep() const { return double(A_.size()) * (cyclic_ ? 0.5 : 1.0); }
  // Steps that reduce the residual's 2-norm by `factor` in exact arithmetic:
  // the least k with T_k(1 / rho) >= factor sqrt(max diag / min diag).
  int stepsFor(double factor) const;
  // Whether it beats multigrid-preconditioned CG on this system: while a
  // 1e4 reduction takes at most kQuickSteps steps. The steps grow as
  // sqrt(nu dt) / h, CG's multigrid iterations do not. Measured on the
  // cavity's viscosity at 512^2 and 64^3: 1.4-1.6x faster at 20 to 40 steps
  // per solve, level at 60 to 70, slower at 95 (docs/performance.md); so up
  // to nu dt / h^2 of about 30 in 2D and 20 in 3D.
  static constexpr int kQuickSteps = 80;
  bool quick() const { return applicable() && stepsFor(1e4) <= kQuickSteps; }

  // Solves A x = b from *x to the relative residual options.tolerance;
  // iterations counts the Chebyshev steps (plain CG where not applicable).
  // bnorm, when known (>= 0), saves a pass: ||b||_2.
  SolverResult solve(const Vector& b, Vector* x, const SolverOptions& options, double bnorm = -1.0);

 private:
  // Runs op(t, q), t = 1..m, on every plane q along the last axis, step t
  // on a plane after step t - 1 on the plane and its neighbours, m steps
  // in one pass over memory (see above).
  template <class Op>
  void pipeline(int m, Op&& op);
  // fn(row, y, z) for each row of plane q.
  void rows(size_t q, auto&& fn) const;
  // Chebyshev step `level` (>= 2) on plane q; `jacobi`: cyclic, a round's
  // closing half step (e = J e_{k-1}).
  void step(int level, size_t q, bool jacobi = false);
  // The same on the cells of colour level & 1 (cyclic).
  void colourStep(int level, size_t q, bool jacobi);
  // x += e / rscale on plane q.
  void addCorrection(Vector* x, const float* e0, const float* e1, size_t q) const;
  // r = b - A x on plane q; writes step 1 (e_1 = g = rscale D^-1 r / scale)
  // and the plane's ||r||^2.
  void residualPlane(const Vector& b, const Vector& x, size_t q);
  double residualNorm() const;  // of the last residual, from the planes' sums

  const LaplaceSystem<D>& A_;
  ChebyshevLayout layout_;
  double rho_ = 1.0;
  double diagRatio_ = 1.0;    // max / min diagonal over active cells
  bool cyclic_ = false;
  size_t hx_ = 0;  // cyclic: a row's slots in each colour's vector
  ChebyshevWork own_;
  ChebyshevWork* work_;       // &own_ unless shared
  std::vector<float> zeros_;  // a row of zeros: beyond a non-periodic edge
  const float* zerosOf() const { return zeros_.data(); }
  // Per row, from packedStart_[row]: the coefficients of its cells outside
  // the uniform span (1 / diag, then the face weights), 2D + 1 floats each;
  // rows with the same stored rows share them.
  std::vector<size_t> packedStart_;
  std::vector<float> packed_;
  const float* packedRow(size_t row) const { return packed_.data() + packedStart_[row]; }
  void packRow(size_t row, float* out) const;
  std::vector<float> omega_;  // omega_[k] of step k
  std::vector<double> planeSquares_;
  double rscale_ = 1.0;
};

}  // namespace morphoflow
