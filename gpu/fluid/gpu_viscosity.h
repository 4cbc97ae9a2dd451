// The implicit viscosity on the GPU (fluid/viscosity.h): (I - nu dt lap) u =
// u* on each component's free faces, with the CPU's own systems (the faces
// inside a cut obstacle held, the cut surface's couplings in their boundary
// terms), one component after another, each solved by CG with the diagonal
// as preconditioner to the relative residual (shaders/viscosity.comp sets a
// component's system up and stores its solution). The components' solves
// share one set of work vectors, one right-hand side and solution, one read
// of their tallies, and their schedule where one has none of its own.
#pragma once

#include <array>
#include <memory>

#include "core/solver_result.h"
#include "fluid/viscosity.h"
#include "gpu/fluid/gpu_mac_grid.h"

namespace morphoflow {

class GpuLaplace;
class GpuPcg;
struct GpuPcgWork;

template <int D>
class GpuViscosity {
 public:
  GpuViscosity(const VelocityConstraints<D>& vc, GpuMacGrid<D>* grid, GpuPrecision real);
  ~GpuViscosity();
  // grid->vel diffused over dt (nu > 0) to `tolerance`, and constrained; the
  // solve's result is the last tally's (tally(): one host wait).
  SolverResult diffuse(double nu, double dt, double tolerance);
  SolverResult tally();
  // The constraints changed in the cells [lo, hi) (a moving obstacle): the systems follow.
  void rebuild(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi);
  // The solve's work vectors, for solves that never overlap it (the pressure's).
  std::shared_ptr<GpuPcgWork> work() const;

 private:
  struct Component;  // a component's host system and boundary terms
  void run(FluidOp mode, int a, double s);
  void uploadHeld(const VelocityConstraints<D>& vc, int a, size_t rowBegin, size_t rowEnd);
  GpuMacGrid<D>& grid_;
  GpuPrecision real_;
  std::array<std::unique_ptr<Component>, D> components_;
  std::shared_ptr<GpuPcgWork> work_;
  GpuBuffer b_, x_;  // the component being solved: its right-hand side and solution
  GpuBuffer held_;   // with cut obstacles: the held faces (prescribed, or inside an obstacle)
  double s_ = -1.0;  // nu dt / h^2 of the systems
};

}  // namespace morphoflow
