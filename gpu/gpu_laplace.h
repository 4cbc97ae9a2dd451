// A LaplaceSystem (core/laplace_system.h) on the GPU: its face weights and
// diagonal in storage buffers, and the kernels of shaders/laplace.comp on
// real vectors (the PCG's: float or double, precision()) or float ones (the
// multigrid levels').
#pragma once

#include <array>
#include <vector>

#include "core/anisotropic_system.h"
#include "core/backend.h"
#include "core/laplace_system.h"
#include "gpu/gpu_buffer.h"
#include "gpu/gpu_reduction.h"
#include "gpu/kernel_modes.h"

namespace morphoflow {

class ComputeProgram;

// What applyUpdatingP's kernel takes besides the operator's buffers.
struct PUpdate {
  const GpuBuffer* pNew;
  const GpuBuffer* scalars;
  std::array<int, 4> slots;
  bool first = false;
};

// What a PCG's first and last residual kernels do besides r = b - A x and
// r . r's partials (laplace.comp's MODE_RESIDUAL with DOT_PARTIAL; -1: not):
// b . b's partials into slot bb; z = r / diag (the diagonal preconditioner)
// and r . z's partials into slot rz; x = 0 first where scalars[noRhs] (b . b)
// is 0 (then r = b); the partials of x's sum on the active cells into slot
// xSum (not with rz); b made mean-free first, its sum's partials at slot
// bSum, the active cells' count at slot count.
struct ResidualExtras {
  const GpuBuffer* scalars = nullptr;
  int bb = -1, rz = -1, noRhs = -1;
  const GpuBuffer* z = nullptr;
  int xSum = -1, bSum = -1, count = -1;
};

class GpuLaplace {
 public:
  GpuLaplace() = default;
  template <int D>
  explicit GpuLaplace(const LaplaceSystem<D>& A);
  // A tensor operator: the axis part, and the mixed terms in apply() and
  // residual() on real vectors (the float kernels, the multigrid's, take
  // the axis part: the preconditioner is the axis part's, as on the CPU).
  template <int D>
  explicit GpuLaplace(const AnisotropicSystem<D>& A);
  // The system's coefficients changed, not its shape (only in the rows
  // [rowBegin, rowEnd) along x: the rest is not uploaded again).
  template <int D>
  void update(const LaplaceSystem<D>& A);
  template <int D>
  void update(const LaplaceSystem<D>& A, size_t rowBegin, size_t rowEnd);
  template <int D>
  void update(const AnisotropicSystem<D>& A);

  size_t size() const { return n_; }
  // The real vectors' precision (apply, residual and the PCG's; Double unless
  // set), and the solution's that residual() and a GpuPcg take (the vectors'
  // unless given: a float pressure solve keeps its solution in double).
  void setPrecision(GpuPrecision vectors) { setPrecision(vectors, vectors); }
  void setPrecision(GpuPrecision vectors, GpuPrecision solution) {
    real_ = vectors;
    solution_ = solution;
  }
  GpuPrecision precision() const { return real_; }
  GpuPrecision solutionPrecision() const { return solution_; }
  bool singular() const { return singular_; }
  int dimension() const { return dim_; }
  const std::array<int, 3>& dims() const { return dims_; }
  const std::array<bool, 3>& periodic() const { return periodic_; }
  double scale() const { return scale_; }
  const GpuBuffer& diag() const { return diag_; }
  // The coefficients, for kernels that build an operator on the GPU (cosine lobes).
  GpuBuffer& weights(int a) { return w_[size_t(a)]; }
  GpuBuffer& cBuffer() { return c_; }
  const GpuBuffer& weights(int a) const { return w_[size_t(a)]; }
  const GpuBuffer& cBuffer() const { return c_; }
  // The mixed terms' couplings (up, down per plane), allocated (zero) if the
  // system had none: for an operator rebuilt on the GPU.
  GpuBuffer& crossBuffer(int k);
  // After kernels wrote the weights and c: diag = c + the face weights (finalize's order).
  void recomputeDiagonal();
  // This system becomes I + k A of `source`, a system of the same shape (AnisotropicSystem::shifted).
  void assignShifted(GpuLaplace& source, double k);
  // True when an odd periodic axis couples cells of one colour (the
  // red-black sweep would then race): such levels smooth by Jacobi.
  bool mixesColours() const;

  void apply(const GpuBuffer& x, GpuBuffer* y) const;  // y = A x (real vectors)
  // y = A x or r = b - A x on real vectors with the partial pass of x . y (apply)
  // or r . r (residual) into `dot`: bitwise a GpuReduction::dot after them,
  // one dispatch fewer.
  void apply(const GpuBuffer& x, GpuBuffer* y, FusedDot dot) const;
  void residual(const GpuBuffer& b, const GpuBuffer& x, GpuBuffer* r, FusedDot dot,
                const ResidualExtras& extras = {}) const;
  // The PCG's operator with its p update fused in (laplace.comp's P_UPDATE;
  // not with mixed terms): pNew = z + beta p and q = A pNew, with pNew . q's
  // partials into `pq`; beta from `scalars` at slots[0] (rzNew, summed from
  // its partials and stored) over slots[1]; then the entered gate's stopping
  // test of the iteration before (GpuGate::checkInNext first), with p . Ap
  // and r . r summed from their partials at slots[2] and slots[3].
  // first: the first iteration's, pNew = z (S[slots[0]] summed and stored; no test).
  void applyUpdatingP(const GpuBuffer& p, const GpuBuffer& z, GpuBuffer* pNew, GpuBuffer* q, FusedDot pq,
                      const GpuBuffer& scalars, std::array<int, 4> slots, bool first = false) const;
  bool hasCross() const { return hasCross_; }
  // One colour of a red-black Gauss-Seidel sweep on float vectors.
  void smooth(const GpuBuffer& b, GpuBuffer* x, int colour) const;
  // The same update on the `count` cells cells[first ..] alone (one colour
  // of a boundary band: core/boundary_band.h).
  void smoothCells(const GpuBuffer& b, GpuBuffer* x, const GpuBuffer& cells, int first, int count) const;
  // y = x + omega (D^-1 (b / scale + N x) - x) on float vectors.
  void jacobi(const GpuBuffer& b, const GpuBuffer& x, GpuBuffer* y, float omega) const;

 private:
  void run(LaplaceMode mode, bool single, const GpuBuffer& x, const GpuBuffer* y, const GpuBuffer* b, int colour,
           float omega, const FusedDot* dot = nullptr, const PUpdate* pUpdate = nullptr,
           const ResidualExtras* extras = nullptr) const;
  std::array<int, 3> dims_{1, 1, 1};
  std::array<bool, 3> periodic_{};
  int dim_ = 2;
  size_t n_ = 0;
  GpuPrecision real_ = GpuPrecision::Double, solution_ = GpuPrecision::Double;
  double scale_ = 1.0;
  bool singular_ = false;
  std::array<GpuBuffer, 3> w_;
  GpuBuffer diag_, c_;
  std::array<GpuBuffer, 6> cross_;  // up, down per plane (a tensor's mixed terms)
  bool hasCross_ = false;
};

}  // namespace morphoflow
