// The multigrid V-cycle of core/multigrid.h as a PCG preconditioner on the
// GPU (MGPCG, McAdams et al. 2010): the same levels (taken from the CPU's
// hierarchy, whose coarse operators re-discretise the fine one), the same
// transfers and red-black Gauss-Seidel smoothing, single precision. The
// coarsest level is solved exactly by its dense (pseudo-)inverse, computed
// once on the host, so the cycle is a fixed symmetric linear operator. The
// levels of at most kTailCells cells run in one work group and one dispatch
// (shaders/vcycle_tail.comp), their vectors and coefficients packed. A
// level's boundary band (core/boundary_band.h) is the CPU level's, swept
// as the CPU sweeps it.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/multigrid.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_reduction.h"

namespace morphoflow {

class GpuMultigrid {
 public:
  // `fine` is the GPU copy of levels.level(0) (the PCG's system); it must outlive this.
  // Levels of at most `tailCells` cells make the one-dispatch tail (0: none).
  template <int D>
  GpuMultigrid(const Multigrid<D>& levels, const GpuLaplace& fine, const MultigridOptions& options,
               size_t tailCells = kTailCells);
  // The CPU hierarchy was refreshed (new coefficients, same shapes).
  template <int D>
  void update(const Multigrid<D>& levels);

  // z = M r for double vectors: one cycle on r / s, times s, where s^2 is
  // scalars[slot] (r . r), so single precision neither under- nor overflows;
  // with the partial pass of r . z into `rz` (gpu_reduction.h).
  void apply(const GpuBuffer& r, GpuBuffer* z, const GpuBuffer& scalars, int slot, FusedDot rz);
  // The levels the one-dispatch tail runs (0: none).
  int tailLevels() const { return int(levels_.size() - tail_); }

 private:
  static constexpr size_t kTailCells = 4096;  // 64^2, 16^3
  static constexpr int kMaxTailLevels = 8;    // vcycle_tail.comp's kMaxLevels

  struct Level {
    const GpuLaplace* A = nullptr;
    std::unique_ptr<GpuLaplace> own;  // levels >= 1
    GpuBuffer x, b, r;
    GpuBuffer band;                  // the band's cells, colour 0's then colour 1's
    std::array<int, 2> bandCount{};  // the cells of each colour
  };
  template <int D>
  void uploadBands(const Multigrid<D>& levels);
  void sweepBand(Level& L, bool reverse);  // options_.bandSweeps sweeps (their adjoints when reverse)
  void cycle(size_t l);
  // skipFirst, skipLast: without the first sweep's first colour or the last sweep's last
  void smooth(Level& L, bool reverse, int sweeps, bool skipFirst = false, bool skipLast = false);
  // Whether apply()'s conversions make the finest level's first and last colours.
  bool sweepsFused() const;
  template <int D>
  void invertCoarsest(const LaplaceSystem<D>& A);
  void chooseTail(size_t tailCells);
  void packTail();  // the tail levels' coefficients into the packed buffers
  void runTail();

  MultigridOptions options_;
  std::vector<Level> levels_;
  GpuBuffer dense_;  // the coarsest level's inverse, row-major, float
  // The tail: levels from tail_ on (levels_.size(): none); level tail_'s
  // x, b and r hold every tail level's, packed (level k at offsets_[k]).
  size_t tail_ = 0;
  std::vector<int> offsets_;
  std::array<GpuBuffer, 3> tailW_;
  GpuBuffer tailDiag_, tailC_;
};

}  // namespace morphoflow
