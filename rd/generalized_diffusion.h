// Generalized (non-Gaussian) diffusion, McGraw's Kramers-Moyal expansion
// (seed 000 sec. 2-5): a species diffuses by
//   du/dt = d (D_ij d_ij u + D_ijk d_ijk u + D_ijkl d_ijkl u)         (eq. 19)
// with symmetric tensors of rank 2, 3 and 4; written out (eq. 20-21)
//   Dxx u_xx + 2 Dxy u_xy + Dyy u_yy
//   + Dxxx u_xxx + 3 Dxxy u_xxy + 3 Dxyy u_xyy + Dyyy u_yyy
//   + Dxxxx u_xxxx + 4 Dxxxy u_xxxy + 6 Dxxyy u_xxyy + 4 Dxyyy u_xyyy + Dyyyy u_yyyy.
// The third and fourth derivatives are 5 x 5 Savitzky-Golay kernels (eq.
// 30-37); the second ones central differences (the paper's substitution that
// lowers the explicit step's spectral radius) or Savitzky-Golay on request.
// The whole operator is one 5 x 5 convolution on a periodic 2D grid (eq. 37),
// homogeneous, so its eigenvalues are the kernel's Fourier symbol at the
// grid's frequencies: the spectral radius of the explicit step I + dt d A
// (eq. 27) and of the implicit ones (eq. 28) is exact.
#pragma once

#include <array>
#include <complex>
#include <string>
#include <vector>

#include "core/solver_result.h"
#include "rd/savitzky_golay.h"

namespace morphoflow {

// The unique components of the symmetric tensors (x before y).
struct KramersMoyalTensors {
  std::array<double, 3> d2{1.0, 0.0, 1.0};  // Dxx, Dxy, Dyy
  std::array<double, 4> d3{};               // Dxxx, Dxxy, Dxyy, Dyyy
  std::array<double, 5> d4{};               // Dxxxx, Dxxxy, Dxxyy, Dxyyy, Dyyyy
};

// Table 2's sequences, named by their column: "a" ... "f".
std::vector<std::string> kramersMoyalPresets();
const KramersMoyalTensors* kramersMoyalPreset(const std::string& name);
// The tensors turned by `angle` radians: D'_{i...} = R_ia ... D_a... (the
// propagator's and the texture's orientations turn with them).
KramersMoyalTensors rotated(const KramersMoyalTensors& t, double angle);

enum class SecondDerivatives { CentralDifferences, SavitzkyGolay };

class GeneralizedDiffusion {
 public:
  // A grid of nx x ny cells of size h, periodic on both axes; Savitzky-Golay
  // fits of total degree `degree` (the paper: 5).
  GeneralizedDiffusion(const KramersMoyalTensors& t, int nx, int ny, double h,
                       SecondDerivatives second = SecondDerivatives::CentralDifferences, int degree = 5);

  // The operator's kernel, weights[dy + 2][dx + 2] in physical units.
  const Kernel5& kernel() const { return k_; }
  // out = A x (without d).
  void apply(const std::vector<double>& x, std::vector<double>* out) const;
  // Solves (I - c A) x = b in place by BiCGSTAB (A is not symmetric when
  // rank-3 terms are present), Jacobi-preconditioned, to the relative
  // residual `tolerance`; deterministic for any thread count.
  SolverResult solve(double c, std::vector<double>* b, double tolerance) const;

  // The eigenvalue of A for the Fourier mode exp(i (kx x + ky y) / h).
  std::complex<double> symbol(double kx, double ky) const;
  // The spectral radius of a theta step of diffusion d dt,
  // (I - theta dt d A)^-1 (I + (1 - theta) dt d A): theta 0 is eq. 27, 1 eq. 28.
  double spectralRadius(double dtd, double theta) const;
  // The largest dt <= dtMax whose spectral radius is at most `bound` (0 when none is).
  double largestStableStep(double d, double theta, double dtMax, double bound) const;

 private:
  int nx_, ny_;
  Kernel5 k_;
  std::vector<std::complex<double>> symbols_;  // at the frequencies the radius is taken over
};

// The Gram-Charlier expansion of the propagator (seed 000 eq. 23-24):
// p(r) = N(0, 2 tau D2)(r) (1 + Q3 . H3(r) / 3! + Q4 . H4(r) / 4!),
// Q^(n) = (-1)^n n! tau D^(n), H the Hermite tensors (appendix; the standard
// form of Grad 1949, whose constant term of H4 is the sum over the three
// pairings of deltas).
double gramCharlierPropagator(const KramersMoyalTensors& t, double tau, double rx, double ry);

}  // namespace morphoflow
