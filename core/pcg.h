// Preconditioned conjugate gradients on a LaplaceSystem (Bridson, "Fluid
// Simulation for Computer Graphics", ch. 5; the seeds' ICCG with M = MIC(0)).
// Singular (pure-Neumann) systems are solved in the mean-free subspace.
#pragma once

#include <functional>

#include "core/laplace_system.h"
#include "core/preconditioner.h"
#include "core/solver_result.h"

namespace morphoflow {

struct SolverOptions {
  double tolerance = 1e-6;  // relative residual ||b - Ax||_2 / ||b||_2
  int maxIterations = 1000;
};

// Work vectors of PCG, kept between solves to avoid reallocating them (the
// preconditioned residual z shares q's storage). With `regenerate`, a b that
// is the workspace's own becomes the residual (one vector less), and the
// final true residual rebuilds b into a vector the iteration no longer needs.
struct PcgWorkspace {
  Vector b, r, p, q;
  std::function<void(Vector*)> regenerate;  // writes the right-hand side into its argument
};

// Solves A x = b starting from *x. M may be null (plain CG). b may be the
// workspace's own b (then it may be changed: a singular system's b loses its
// mean in place, with no copy).
template <int D>
SolverResult solvePCG(const LaplaceSystem<D>& A, const Vector& b, Vector* x, Preconditioner* M,
                      const SolverOptions& options, PcgWorkspace* workspace = nullptr);

template <int D>
struct AnisotropicSystem;
// The same for a tensor diffusion system (M typically built on A.axis).
template <int D>
SolverResult solvePCG(const AnisotropicSystem<D>& A, const Vector& b, Vector* x, Preconditioner* M,
                      const SolverOptions& options, PcgWorkspace* workspace = nullptr);

}  // namespace morphoflow
