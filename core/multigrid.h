// Geometric multigrid V-cycle for a LaplaceSystem, usable alone (repeated
// V-cycles) or as a PCG preconditioner (MGPCG, McAdams, Sifakis & Teran 2010).
//
// Cell-centred hierarchy: coarse cells cover 2^D fine cells; prolongation is
// bi-/trilinear (weights 3/4, 1/4 per axis), restriction its transpose over
// 2^D. Coarse operators re-discretise: a coarse face's open fraction is the
// mean of the fine faces it covers (so obstacles coarsen to partial faces),
// and identity terms are averaged. Smoothing is red-black Gauss-Seidel,
// black-first after the coarse correction, so the cycle is symmetric.
//
// The levels work in single precision (as McAdams et al.): the cycle is
// bandwidth-bound and a preconditioner needs no more. Accuracy comes from
// the double-precision outer iteration: PCG, or defect correction in solve().
#pragma once

#include <array>
#include <memory>
#include <span>
#include <vector>

#include "core/boundary_band.h"
#include "core/pcg.h"
#include "core/preconditioner.h"
#include "core/solver_result.h"
#include "core/work_pool.h"

namespace morphoflow {

struct MultigridOptions {
  int preSmooth = 2;
  int postSmooth = 2;
  int minCoarseCells = 4;  // stop coarsening when an axis would drop below this
  // Boundary smoothing (core/boundary_band.h), for systems whose weights
  // are open fractions: this many red-black sweeps on a level's band after
  // its pre-smoothing, and their adjoints before its post-smoothing, on the
  // levels of more than bandMinCells cells (0 sweeps: none).
  int bandSweeps = 0;
  int bandWidth = 1;
  size_t bandMinCells = 4096;
};

template <int D>
class Multigrid final : public Preconditioner {
 public:
  explicit Multigrid(const LaplaceSystem<D>& fine, const MultigridOptions& options = {});

  // Repeated V-cycles (defect correction: x += cycle(b - A x)) until the
  // relative residual meets the tolerance.
  SolverResult solve(const Vector& b, Vector* x, const SolverOptions& options);
  // Preconditioner: z = one V-cycle from zero.
  void apply(const Vector& r, Vector* z) override;
  double applyDot(const Vector& r, double rnorm, Vector* z) override;
  // z is the fine level's x times the last cycle's scale.
  bool recomputesZ() const override { return true; }
  void direction(double beta, bool first, Vector* p) override;
  // The coarse levels' vectors (about 3/7 of a float a fine cell) live in
  // the storage lent, where it has room, else in the hierarchy's own.
  void scratch(std::span<double> s) override { scratch_ = s; }
  // The bytes the coarse levels' own vectors hold (none while every cycle
  // found a scratch with room).
  size_t coarseBytes() const { return coarse_.capacity() * sizeof(float); }

  // The fine system's coefficients changed, not its shape (a new identity
  // term, say, from a new time step): re-derive the coarse levels in place,
  // as the constructor would, without reallocating anything.
  void refresh();
  // The same when the fine system changed only in the cells [lo, hi): each
  // level re-derives the cells over the changed ones (bitwise what refresh()
  // gives), so a moving obstacle costs the levels what it touches.
  void refresh(IVec<D> lo, IVec<D> hi);

  // The finest level's work vectors (the largest) come from `pool` for one
  // solve and go back to it: a solver lends them only while it solves.
  void borrowFine(WorkPool* pool);
  void giveBackFine(WorkPool* pool);

  int levels() const { return int(levels_.size()); }
  const LaplaceSystem<D>& level(int l) const { return l == 0 ? fine_ : levels_[size_t(l)].A; }
  // Level l's boundary band (empty where it has none to smooth).
  const BoundaryBand<D>& band(int l) const { return levels_[size_t(l)].band; }

 private:
  using FVector = std::vector<float>;
  // Per-axis transfer tables between this level (fine) and the next (coarse).
  struct AxisTransfer {
    // Prolongation: fine index f takes w * x_c[lo] + (1 - w) * x_c[hi].
    std::vector<int> lo, hi;
    std::vector<float> w;
    // Restriction (the transpose): coarse index C gathers up to 4 fine
    // indices with these weights (unused entries weigh 0).
    std::vector<std::array<int, 4>> fine;
    std::vector<std::array<float, 4>> fineWeight;
    // Coarse indices [lo, hi) where the tables hold the interior pattern
    // (fine 2X-1 .. 2X+2 at 1/4, 3/4, 3/4, 1/4; fine 2X, 2X+1 from X at 3/4
    // and X -+ 1 at 1/4): those loops run without the tables, same arithmetic.
    int restrictLo = 0, restrictHi = 0, prolongLo = 0, prolongHi = 0;
  };
  struct Level {
    LaplaceSystem<D> A;  // unused on level 0 (fine_ is used)
    // The level's vectors, A's size each: level 0's in fineX_, fineB_, fineR_, the
    // coarse levels' in a scratch or coarse_ (placed for each cycle).
    float *x = nullptr, *b = nullptr, *r = nullptr;
    std::array<AxisTransfer, D> transfer;  // to level + 1 (absent on the coarsest)
    BoundaryBand<D> band;
  };
  void buildTransfer(int l);
  void findBands();   // the levels' bands from their systems
  BandMarks bandMarks_;  // (kept zero between findBands calls)
  void ensureFine();  // level 0's vectors, sized (allocated on first use)
  // Places the coarse levels' vectors for a cycle: in scratch_ where it has
  // room (its bytes then hold floats until releaseCoarse()), else in coarse_.
  void placeCoarse();
  void releaseCoarse();
  size_t coarseFloats() const;  // the coarse levels' vectors, each padded to 64 bytes
  void cycle(int l);
  // The cycle on r / rscale (single precision must neither underflow nor
  // overflow), z = rscale * result (unless z is null); returns r . z when
  // `withDot`.
  double scaledCycle(const Vector& r, double rscale, Vector* z, bool withDot);
  // z_i = zScale_ x_i on level 0, through a raw pointer (so the loops that
  // use it vectorise; stores through the vectors would reload their data).
  auto zOf() const {
    const float* x = fineX_.data();
    const double scale = zScale_;
    return [x, scale](size_t i) { return double(x[i]) * scale; };
  }
  void restrict(int l);   // r of level l -> b of level l + 1
  void prolongAdd(int l); // x of level l + 1 added into x of level l

  const LaplaceSystem<D>& fine_;
  MultigridOptions options_;
  std::vector<Level> levels_;
  FVector fineX_, fineB_, fineR_;  // level 0's vectors (from a pool while borrowed)
  FVector coarse_;                 // the coarse levels' vectors where no scratch is lent
  std::span<double> scratch_;
  bool inScratch_ = false;            // the coarse levels' vectors are in scratch_
  Vector coarseB_, coarseX_, r_, z_;  // the coarsest solve in double; solve()'s vectors
  PcgWorkspace coarseWork_;
  double zScale_ = 0.0;  // the last cycle's rscale (z = zScale_ x on level 0)
};

}  // namespace morphoflow
