// The pressure projection on the GPU (fluid/pressure_projection.h): the
// divergence through the faces' open fractions, phi warm-started from the
// last two projections, MGPCG to the scene's tolerance on the CPU's own
// system and multigrid levels (phi in double: kPhiPrecision), then the
// gradient on every free face (shaders/pressure_projection.comp, the
// formulas kernels/projection.inc's).
#pragma once

#include <memory>
#include <vector>

#include "core/laplace_system.h"
#include "core/multigrid.h"
#include "core/pcg.h"
#include "core/solver_result.h"
#include "core/state_archive.h"
#include "gpu/fluid/gpu_mac_grid.h"

namespace morphoflow {

class GpuLaplace;
class GpuMultigrid;
class GpuPcg;
struct GpuPcgWork;

template <int D>
class GpuProjection {
 public:
  // `work`: the solve's work vectors (shared with solves that never overlap it).
  GpuProjection(const VelocityConstraints<D>& vc, GpuMacGrid<D>* grid, GpuPrecision real,
                std::shared_ptr<GpuPcgWork> work);
  ~GpuProjection();
  // grid->vel made divergence-free (to `options`) and constrained; the
  // solve's result is the last tally's (tally(): one host wait).
  SolverResult project(double dt, const SolverOptions& options);
  SolverResult tally();
  // The constraints changed in the cells [lo, hi) (a moving obstacle): the system and its levels follow.
  void rebuild(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi);
  std::vector<double> phi() const;  // p = rho phi / dt
  double lastDt() const { return lastDt_; }
  void save(StateWriter* out) const;  // phi, the rate before and the clock of the warm start
  void load(const StateReader& in);

 private:
  void run(FluidOp mode, int axis, size_t n, double dt);
  GpuMacGrid<D>& grid_;
  GpuPrecision real_;
  LaplaceSystem<D> P_;                    // the host's system and levels: a moving obstacle's only
  std::unique_ptr<Multigrid<D>> levels_;  // (refers to P_)
  std::unique_ptr<GpuLaplace> A_;
  std::unique_ptr<GpuMultigrid> multigrid_;
  std::unique_ptr<GpuPcg> pcg_;
  GpuBuffer inactive_;              // the cells without a pressure
  GpuBuffer phi_, rhs_, ratePrev_;  // phi in kPhiPrecision, rhs in real_, the rate before in float (the CPU's)
  double lastDt_ = 0.0;
  int solves_ = 0;
};

}  // namespace morphoflow
