// LaplaceSystem<D>: the symmetric positive (semi-)definite 5-/7-point systems
// that the pressure projection, implicit viscosity and implicit diffusion all
// solve, written once for 2D and 3D:
//
//   (A x)_i = scale * ( c_i x_i + sum_{faces f of i} w_f (x_i - x_j(f)) )
//
// w_f in [0, 1] is the open fraction of the face between two cells (0 for a
// solid face or a Neumann wall), c_i collects identity terms (implicit
// diffusion: h^2 / (nu dt)) and Dirichlet couplings. A cell whose diagonal is
// zero is inactive: its unknown is pinned at 0 and it couples to nothing.
#pragma once

#include <array>
#include <type_traits>
#include <vector>

#include "core/grid.h"
#include "core/row_field.h"

namespace morphoflow {

using Vector = std::vector<double>;

template <int D, class T>
struct RowStencil;  // core/row_stencil.h

template <int D>
struct LaplaceSystem {
  IVec<D> dims{0};
  std::array<bool, D> periodic{};
  double scale = 1.0;               // 1 / h^2 for a Laplacian
  // Coefficient fields, each row stored once per distinct content (written
  // dense, compacted by finalize()).
  RowField<D> c;                 // diagonal-only term
  std::array<RowField<D>, D> w;  // w[a](i): coupling of i and i + e_a (wrapped if periodic)
  RowField<D> diag;              // c + sum of the 2D face weights; 0 = inactive

  LaplaceSystem() = default;
  LaplaceSystem(const IVec<D>& dims, const std::array<bool, D>& periodic, double scale);

  size_t size() const { return c.size(); }
  // Zeroes couplings across non-periodic domain edges, computes diag and
  // compacts the fields. Call after filling c and w (a field already
  // compacted by an earlier finalize() may stay so).
  void finalize();
  // finalize() on the rows of the cells [lo, hi), whose c and w were written
  // again in place (compact: rewriteRows), and on the rows whose diagonal
  // reads their weights: the diagonal, spans and counts a whole finalize()
  // gives, without a pass over the other rows.
  void finalizeRows(const IVec<D>& lo, const IVec<D>& hi);
  // The rows of the cells [lo, hi) and the next along each axis beyond x
  // (a cell's diagonal reads the weights of the faces below it), ascending.
  std::vector<size_t> rowsReading(const IVec<D>& lo, const IVec<D>& hi) const;
  // True when no c_i > 0: constants are then in the null space, and solvers
  // work on mean-free vectors.
  bool singular() const { return singular_; }

  // The kernels run in double (the solvers' outer loops) or float (the
  // multigrid preconditioner's levels, half the memory traffic).
  template <class T>
  void apply(const std::vector<T>& x, std::vector<T>* y) const;
  // y = A x; returns x . y (one pass instead of two).
  double applyDot(const Vector& x, Vector* y) const;
  // r = b - A x (0 on inactive cells).
  template <class T>
  void defect(const T* b, const T* x, T* r) const;
  template <class T>
  void defect(const std::vector<T>& b, const std::vector<T>& x, std::vector<T>* r) const {
    defect(b.data(), x.data(), r->data());
  }
  // r = b - A x; returns ||r||_2.
  double residual(const Vector& b, const Vector& x, Vector* r) const;
  // The same with r in b's place (bitwise residual()'s values and norm).
  double residualInPlace(Vector* b, const Vector& x) const;
  // r = b - A x on one row (r: that row's nx values); returns its ||r||^2.
  double residualRow(size_t row, const Vector& b, const Vector& x, double* r) const;
  // One red-black Gauss-Seidel sweep; `reverse` runs black first (so a
  // reversed post-smoother makes a symmetric V-cycle).
  template <class T>
  void gaussSeidel(const T* b, T* x, bool reverse) const;
  template <class T>
  void gaussSeidel(const std::vector<T>& b, std::vector<T>* x, bool reverse) const {
    gaussSeidel(b.data(), x->data(), reverse);
  }
  // Red-black Gauss-Seidel sweeps on the cells [lo, hi) alone, the others
  // held: a solve's start made consistent with rows that were rewritten.
  // With omega != 1, over-relaxed (SOR: x_i += omega (the sweep's x_i - x_i)).
  void relaxBox(const Vector& b, Vector* x, const IVec<D>& lo, const IVec<D>& hi, int sweeps, double omega = 1.0) const;
  // Removes the mean over active cells (for singular systems).
  void removeNullSpace(Vector* x) const;

  // Each row's longest run [lo, hi) of interior cells whose faces all weigh
  // w (> 0) and which share one c: the kernels skip the weight loads there,
  // with the same arithmetic (the smoother four or eight cells at a time).
  struct Span {
    uint32_t lo = 0, hi = 0;
    float w = 1.0f;
  };
  // 1 / diag of cell i (0 on inactive cells), in single precision (a
  // smoother's or preconditioner's factor: the double kernels widen it).
  // Formed when asked, not stored: the kernels need it only outside the
  // uniform spans (where it is one value) and once per residual pass.
  float invDiag(size_t i) const { return inverse(diag[i]); }
  static float inverse(float d) { return d > 0 ? 1.0f / d : 0.0f; }
  // A row's span for sweeps that read the neighbours' values only (the
  // smoother, the Chebyshev iteration): its faces across a non-periodic
  // domain edge may weigh 0, as the row of zeros beyond adds 0 either way.
  const Span& sweepSpan(size_t row) const { return sweepSpan_[row]; }

 private:
  // y = A x on one row (y: the row's nx values, x and b: whole vectors);
  // returns the row's x . y when Dot (else 0). With b, the row's uniform
  // span gets b - A x instead (its cells are all active).
  template <class T, bool Dot>
  double applyRow(size_t row, const T* x, T* y, const T* b = nullptr) const;
  // r = b - A x on one row (r: the row's values); returns the row's r . r
  // when SumSquares (else 0).
  template <class T, bool SumSquares>
  double defectRow(size_t row, const T* b, const T* x, T* r) const;
  template <class T>
  const T* zeros() const;
  // An odd periodic axis beyond x couples rows of one colour across the
  // wrap: red-black sweeps then take the rows one by one (deterministic, race-free).
  bool coloursMeetAcrossRows() const;
  RowStencil<D, double> stencil(size_t row) const;  // x and the weights beyond an edge: zeros
  void diagRow(size_t row, float* d) const;
  Span longestSpan(size_t row, bool edges) const;
  void findSpans(const std::vector<size_t>& rows);
  uint16_t positiveCount(const float* row) const;
  void countActive();  // active_ and singular_ from the rows' counts

  bool singular_ = false;
  size_t active_ = 0;
  std::vector<uint16_t> activeOf_, positiveCOf_;  // per row: active cells, and cells with c > 0
  Vector zerosX_;               // a row of zeros: the neighbour beyond a wall
  std::vector<float> zerosW_;   // (also the float row of zeros)
  std::vector<Span> uniformSpan_;
  // The same for the smoother, which may also take faces across a
  // non-periodic domain edge (there its sums match the general ones too).
  std::vector<Span> sweepSpan_;
};

// Builds the plain Laplacian with Neumann walls (periodic where asked) on a
// full box: w = 1 everywhere inside, c = 0. Convenience for tests and the
// multigrid's coarse levels.
template <int D>
LaplaceSystem<D> makeNeumannLaplacian(const IVec<D>& dims, const std::array<bool, D>& periodic,
                                      double h);

// Vector helpers (deterministic reductions).
double dot(const Vector& a, const Vector& b);
double norm2(const Vector& a);
void axpy(double alpha, const Vector& x, Vector* y);  // y += alpha x

}  // namespace morphoflow
