// Pressure projection (Stam 1999; Kim & Lin eq. 18): solve
//   -lap(phi) = -div(u*),  u = u* - grad(phi),  p = rho phi / dt
// on the fluid cells, Neumann at walls, inflow and solids, p = 0 at outflow,
// to a relative residual tolerance, by MGPCG (default), MIC(0)-PCG or
// multigrid V-cycles. The previous phi warm-starts the next solve.
#pragma once

#include <algorithm>
#include <memory>

#include "core/laplace_system.h"
#include "core/multigrid.h"
#include "core/mic0.h"
#include "core/solver_result.h"
#include "core/state_archive.h"
#include "core/work_pool.h"
#include "fluid/fluid_settings.h"
#include "fluid/velocity_constraints.h"

namespace morphoflow {

// -lap on the fluid cells (scale 1 / h^2): Neumann at walls, inflow and
// solids, p = 0 at outflow through a mirrored ghost.
template <int D>
LaplaceSystem<D> pressureSystem(const VelocityConstraints<D>& constraints);
// The rows of the cells [lo, hi) (and their neighbours') written again
// from the constraints, which changed only there (a moving obstacle).
template <int D>
void updatePressureSystem(LaplaceSystem<D>* A, const VelocityConstraints<D>& constraints, const IVec<D>& lo,
                          const IVec<D>& hi);
// The box of cells whose rows updatePressureSystem writes for the cells
// [lo, hi): one cell more on every side (side -1 for lo, +1 for hi).
template <int D>
IVec<D> pressureRowsChanged(const IVec<D>& corner, const IVec<D>& cells, int side) {
  IVec<D> k;
  for (int a = 0; a < D; ++a) k[a] = std::clamp(corner[a] + side, 0, cells[a]);
  return k;
}

// The warm start relaxed over the rows a moving obstacle rewrote, before
// the solve: red-black SOR sweeps there (0 sweeps: none).
struct MovedRowsRelaxation {
  int sweeps = 10;
  double omega = 1.6;
};

// The pressure's V-cycle: its weights are open fractions, and the band of
// a cut body's cells takes four more sweeps a level (docs/performance.md).
inline constexpr MultigridOptions kPressureCycle{.bandSweeps = 4};

template <int D>
class PressureProjection {
 public:
  PressureProjection(const VelocityConstraints<D>& constraints, PressureSolver solver,
                     const SolverOptions& options);

  // Its work vectors come from `pool` (when given) and go back to it.
  SolverResult project(MacVelocity<D>* u, double dt, double density, WorkPool* pool = nullptr);
  // The system again from the constraints (a moving obstacle changed them
  // in the cells [lo, hi)); the warm start stays.
  void rebuild(const IVec<D>& lo, const IVec<D>& hi);
  void setMovedRowsRelaxation(const MovedRowsRelaxation& r) { relaxation_ = r; }
  // Cell divergence of u (0 on solid cells).
  void divergence(const MacVelocity<D>& u, Vector* div) const;
  // Takes phi of a projection computed elsewhere (the GPU backend) as the
  // last one's, for pressure() and the force probes.
  void adopt(const Vector& phi, double dt, double density);
  // Pressure of the last projection, p = rho phi / dt.
  Grid<float, D> pressure() const;
  const LaplaceSystem<D>& system() const { return A_; }
  // The warm start of the next projection (checkpoints).
  void save(StateWriter* out) const;
  void load(const StateReader& in);

 private:
  // div = factor * (cell divergence of u, without the 1/h), 0 on solid cells.
  void divergenceTimes(const MacVelocity<D>& u, double factor, Vector* div) const;
  const VelocityConstraints<D>& vc_;
  PressureSolver solver_;
  SolverOptions options_;
  LaplaceSystem<D> A_;
  std::unique_ptr<Multigrid<D>> multigrid_;
  std::unique_ptr<MIC0Preconditioner<D>> mic_;
  Vector phi_;
  // phi / dt of the projection before the last (once solves >= 2); a warm
  // start's guess only, so single precision.
  std::vector<float> ratePrev_;
  PcgWorkspace workspace_;  // its b holds the right-hand side
  double lastDt_ = 0.0, lastDensity_ = 1.0;
  int solves_ = 0;  // projections with dt > 0 since the start, capped at 2
  IVec<D> movedLo_{0}, movedHi_{0};  // the rows the last move rewrote, until the next projection
  MovedRowsRelaxation relaxation_;
};

}  // namespace morphoflow
