// Implicit viscosity (Stam 1999): (I - nu dt lap) u = u*, per velocity
// component on its face grid, no-slip at walls through mirrored ghost values
// (moving walls reflect their velocity), zero gradient at outflow. Solved by
// the Chebyshev iteration (core/chebyshev.h) while the identity term keeps
// the system well conditioned (Chebyshev::quick(): nu dt / h^2 up to about
// 30 in 2D and 20 in 3D), else by multigrid-preconditioned CG, whose
// iteration count does not grow with nu dt. The systems are built
// once; a new nu dt (a CFL-limited step) only rescales their diagonal and
// re-derives the multigrid levels in place. Each solve starts from u* plus
// the viscous increment (per unit nu dt / h^2, so a changing dt keeps it),
// which changes slowly: in 2D extrapolated from the last two steps, in 3D
// the last step's alone (kExtrapolates). The
// tolerance is a relative residual of the whole velocity system, not of
// each component: sum_a ||r_a||^2 <= tol^2 sum_a ||b_a||^2.
#pragma once

#include <array>

#include <memory>
#include <vector>

#include "core/bfloat16.h"
#include "core/chebyshev.h"
#include "core/multigrid.h"
#include "core/pcg.h"
#include "core/solver_result.h"
#include "core/state_archive.h"
#include "core/work_pool.h"
#include "fluid/velocity_constraints.h"

namespace morphoflow {

// Velocity component a's implicit system, A = s (c + sum w (x_i - x_j)): its
// unknowns (the face grid, less the duplicate layer of a periodic axis),
// couplings, and per unknown the diagonal terms and right-hand side that
// walls and prescribed neighbours add; c and s follow the step (setRate).
template <int D>
struct ViscousSystem {
  IVec<D> dims;
  LaplaceSystem<D> A;
  // Per unknown, rows stored once per distinct content (they differ only
  // next to walls and prescribed faces):
  RowField<D> cBoundary;    // diagonal terms from walls and prescribed neighbours; -1 on a prescribed face (inactive)
  RowField<D> boundaryRhs;  // their prescribed values, times the coupling
  // With cut obstacles: 1 on a face inside one, which the viscosity holds
  // as the projection made it, as it holds a prescribed face (the no-slip is
  // at the surface, where the neighbours' stencils put it); empty without
  // cut obstacles.
  std::vector<uint8_t> insideCut;
  // A for s = nu dt / h^2: c = 1/s + boundary terms, 0 on prescribed faces.
  void setRate(double s);
  // The same at the rate set (A.scale) on the unknowns [lo, hi) alone, whose
  // rows were written again (updateViscousSystem), and the diagonal and
  // spans that read them.
  void setRateRows(const IVec<D>& lo, const IVec<D>& hi);
};
template <int D>
ViscousSystem<D> viscousSystem(const VelocityConstraints<D>& constraints, int axis);
// Its rows again where changed constraints touch them: the unknowns of the
// faces of the cells [lo, hi) and one more layer (their neighbours' rows
// see them), which it returns in [*ulo, *uhi) when asked. The system's c,
// diagonal and uniform spans follow at the next setRate or setRateRows.
template <int D>
void updateViscousSystem(ViscousSystem<D>* system, const VelocityConstraints<D>& constraints, int axis,
                         const IVec<D>& lo, const IVec<D>& hi, IVec<D>* ulo = nullptr, IVec<D>* uhi = nullptr);

template <int D>
class ViscositySolver {
 public:
  ViscositySolver(const VelocityConstraints<D>& constraints, const SolverOptions& options);
  // The systems' rows again where the constraints changed (the faces of the
  // cells [lo, hi): a moving obstacle); the warm starts stay.
  void rebuild(const IVec<D>& lo, const IVec<D>& hi);
  // Diffuses u in place; returns the worst of the component solves. Its
  // work vectors come from `pool` (when given) and go back to it.
  SolverResult diffuse(MacVelocity<D>* u, double viscosity, double dt, WorkPool* pool = nullptr);
  // The last diffuse's work: its solves' iterations times the unknowns each
  // updates (a cyclic Chebyshev step half of them), summed over the
  // components, and whether multigrid-preconditioned CG
  // (not the Chebyshev iteration) did any of it.
  double lastCellUpdates() const { return cellUpdates_; }
  bool lastUsedCG() const { return usedCG_; }
  // The warm starts of the next solve (checkpoints).
  void save(StateWriter* out) const;
  void load(const StateReader& in);

 private:
  struct Component : ViscousSystem<D> {
    // The last solve's (x - u*) / s and, where kExtrapolates, its change
    // from the one before: the next warm start, rate + change (a guess
    // only: the rate in single precision, its change, a small correction,
    // in bfloat16).
    std::vector<float> rate;
    std::vector<uint16_t> change;
    int history = 0;            // how many solves they hold (0, 1, 2)
    IVec<D> movedLo{0}, movedHi{0};           // the unknowns whose rows the last move rewrote (until the next solve)
    std::unique_ptr<Chebyshev<D>> chebyshev;  // bounds the spectrum; solves while it is quick
    std::unique_ptr<Multigrid<D>> multigrid;  // present while it solves instead
  };
  // Whether the warm start extrapolates the rate over the last two steps.
  // In 2D that saves 5-12% of the Chebyshev steps; in 3D it saves none
  // (bench fluid at 64^3 and 128^3, 3 and 60 steps of warm-up) and would
  // keep 6 bytes a cell more (docs/performance.md).
  static constexpr bool kExtrapolates = D == 2;
  SolverResult solveComponents(MacVelocity<D>* u, double s);
  // C's Chebyshev bounds and multigrid (whichever solves) after its
  // coefficients changed: on the unknowns [*lo, *hi) alone where given.
  void refreshSolvers(Component& C, const IVec<D>* lo = nullptr, const IVec<D>* hi = nullptr);
  // ||b||^2 of component a's right-hand side (none stored).
  double rightHandSideSquared(const MacVelocity<D>& u, int a, double s) const;
  const VelocityConstraints<D>& vc_;
  SolverOptions options_;
  std::array<Component, D> comp_;
  // The components are solved one after another and share their work
  // vectors: one component's worth, not D.
  Vector b_, x_;
  ChebyshevWork chebyshevWork_;
  PcgWorkspace pcgWork_;
  double s_ = -1.0;  // nu dt / h^2 the diagonals were built for
  double cellUpdates_ = 0.0;
  bool usedCG_ = false;
};

}  // namespace morphoflow
