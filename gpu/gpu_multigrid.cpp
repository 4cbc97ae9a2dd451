#include "gpu/gpu_multigrid.h"

#include <cmath>
#include <utility>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "core/parallel.h"
#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_programs.h"
#include "gpu/kernel_modes.h"

namespace morphoflow {

namespace {

// The coarsest level's matrix, dense, in double; a singular (pure Neumann)
// level gets alpha 1 1^T on its active cells, which keeps its inverse
// symmetric and maps a mean-free b to the mean-free solution.
template <int D>
std::vector<double> denseMatrix(const LaplaceSystem<D>& A) {
  const size_t n = A.size();
  std::vector<double> M(n * n, 0.0);
  double maxDiag = 0.0;
  forEachCell<D>(A.dims, [&](const IVec<D>& k, size_t i) {
    if (A.diag[i] <= 0) return;
    M[i * n + i] += A.scale * A.diag[i];
    maxDiag = std::max(maxDiag, A.scale * A.diag[i]);
    for (int a = 0; a < D; ++a) {
      IVec<D> up = k;
      up[a] = (up[a] + 1) % A.dims[a];
      const size_t j = A.diag.index(up);
      const double w = A.scale * A.w[a][i];
      if (w == 0.0) continue;
      M[i * n + j] -= w;
      M[j * n + i] -= w;
    }
  });
  if (A.singular()) {
    size_t active = 0;
    for (size_t i = 0; i < n; ++i) active += A.diag[i] > 0;
    const double alpha = maxDiag / double(active);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        if (A.diag[i] > 0 && A.diag[j] > 0) M[i * n + j] += alpha;
  }
  for (size_t i = 0; i < n; ++i)
    if (A.diag[i] <= 0) M[i * n + i] = 1.0;  // inactive: pinned, zeroed in the inverse below
  return M;
}

// Gauss-Jordan inversion with partial pivoting; a pivot below `tiny` (a
// further null direction, say a region walled off by obstacles) is left
// out (its row and column of the inverse are 0).
std::vector<double> invert(std::vector<double> M, size_t n) {
  std::vector<double> I(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) I[i * n + i] = 1.0;
  double big = 0.0;
  for (size_t i = 0; i < n; ++i) big = std::max(big, std::abs(M[i * n + i]));
  const double tiny = 1e-12 * big;
  std::vector<bool> dropped(n, false);
  for (size_t c = 0; c < n; ++c) {
    size_t piv = c;
    for (size_t r = c + 1; r < n; ++r)
      if (std::abs(M[r * n + c]) > std::abs(M[piv * n + c])) piv = r;
    if (std::abs(M[piv * n + c]) <= tiny) {
      dropped[c] = true;
      continue;
    }
    if (piv != c)
      for (size_t k = 0; k < n; ++k) {
        std::swap(M[c * n + k], M[piv * n + k]);
        std::swap(I[c * n + k], I[piv * n + k]);
      }
    const double inv = 1.0 / M[c * n + c];
    for (size_t k = 0; k < n; ++k) {
      M[c * n + k] *= inv;
      I[c * n + k] *= inv;
    }
    for (size_t r = 0; r < n; ++r) {
      if (r == c || M[r * n + c] == 0.0) continue;
      const double f = M[r * n + c];
      for (size_t k = 0; k < n; ++k) {
        M[r * n + k] -= f * M[c * n + k];
        I[r * n + k] -= f * I[c * n + k];
      }
    }
  }
  for (size_t c = 0; c < n; ++c)
    if (dropped[c])
      for (size_t k = 0; k < n; ++k) I[c * n + k] = I[k * n + c] = 0.0;
  return I;
}

// Coarsest levels larger than this are smoothed many times instead (odd
// periodic grids, which stop coarsening early).
constexpr size_t kDenseMax = 1024;
constexpr int kCoarseSweeps = 40;

}  // namespace

template <int D>
GpuMultigrid::GpuMultigrid(const Multigrid<D>& levels, const GpuLaplace& fine, const MultigridOptions& options,
                           size_t tailCells)
    : options_(options) {
  for (int l = 0; l < levels.levels(); ++l) {
    Level L;
    if (l == 0) {
      L.A = &fine;
    } else {
      L.own = std::make_unique<GpuLaplace>(levels.level(l));
      L.A = L.own.get();
    }
    const size_t n = levels.level(l).size() * sizeof(float);
    L.x = GpuBuffer(n);
    L.b = GpuBuffer(n);
    if (L.A->mixesColours()) L.r = GpuBuffer(n);  // the damped Jacobi's other vector (the tail's: its own)
    levels_.push_back(std::move(L));
  }
  invertCoarsest(levels.level(levels.levels() - 1));
  chooseTail(tailCells);
  uploadBands(levels);
}

template <int D>
void GpuMultigrid::uploadBands(const Multigrid<D>& levels) {
  for (int l = 0; l < levels.levels(); ++l) {
    const BoundaryBand<D>& band = levels.band(l);
    Level& L = levels_[size_t(l)];
    L.bandCount = {int(band.colour[0].size()), int(band.colour[1].size())};
    if (band.empty()) {
      L.band = GpuBuffer();
      continue;
    }
    std::vector<uint32_t> cells = band.colour[0];
    cells.insert(cells.end(), band.colour[1].begin(), band.colour[1].end());
    L.band = GpuBuffer::of(cells);
  }
}

template <int D>
void GpuMultigrid::update(const Multigrid<D>& levels) {
  for (int l = 1; l < levels.levels(); ++l) levels_[size_t(l)].own->update(levels.level(l));
  invertCoarsest(levels.level(levels.levels() - 1));
  packTail();
  uploadBands(levels);
}

template <int D>
void GpuMultigrid::invertCoarsest(const LaplaceSystem<D>& A) {
  if (A.size() > kDenseMax) {
    dense_ = GpuBuffer();
    return;
  }
  const std::vector<double> inv = invert(denseMatrix<D>(A), A.size());
  dense_ = GpuBuffer::of(std::vector<float>(inv.begin(), inv.end()));
}

void GpuMultigrid::chooseTail(size_t tailCells) {
  // From level 1 on, the last levels that are small, solved exactly at the
  // end and smoothed red-black (vcycle_tail.comp has no Jacobi smoother).
  tail_ = levels_.size();
  if (!dense_.id()) return;
  while (tail_ > 1 && levels_.size() - tail_ < size_t(kMaxTailLevels)) {
    const GpuLaplace& A = *levels_[tail_ - 1].A;
    if (A.size() > tailCells || A.mixesColours()) break;
    --tail_;
  }
  if (levels_.size() - tail_ < 2) {  // one level: nothing to fuse
    tail_ = levels_.size();
    return;
  }
  offsets_.clear();
  size_t total = 0;
  for (size_t l = tail_; l < levels_.size(); ++l) {
    offsets_.push_back(int(total));
    total += levels_[l].A->size();
  }
  Level& T = levels_[tail_];
  for (GpuBuffer* v : {&T.x, &T.b, &T.r}) *v = GpuBuffer(total * sizeof(float));
  for (size_t l = tail_ + 1; l < levels_.size(); ++l)
    for (GpuBuffer* v : {&levels_[l].x, &levels_[l].b, &levels_[l].r}) *v = GpuBuffer();
  for (GpuBuffer* v : {&tailW_[0], &tailW_[1], &tailW_[2], &tailDiag_, &tailC_}) *v = GpuBuffer(total * sizeof(float));
  packTail();
}

void GpuMultigrid::packTail() {
  for (size_t l = tail_; l < levels_.size(); ++l) {
    GpuLaplace& A = *levels_[l].own;
    const size_t bytes = A.size() * sizeof(float), at = size_t(offsets_[l - tail_]) * sizeof(float);
    for (int a = 0; a < A.dimension(); ++a) tailW_[size_t(a)].copyFrom(A.weights(a), bytes, 0, at);
    tailDiag_.copyFrom(A.diag(), bytes, 0, at);
    tailC_.copyFrom(A.cBuffer(), bytes, 0, at);
  }
}

void GpuMultigrid::runTail() {
  const GpuLaplace& A = *levels_[tail_].A;
  const int count = int(levels_.size() - tail_);
  const ComputeProgram& p = useProgram("vcycle_tail.comp", fmt::format("#define DIM {}", A.dimension()));
  std::vector<int> dims;
  std::vector<double> scales;
  double bytes = 0.0;
  for (size_t l = tail_; l < levels_.size(); ++l) {
    const GpuLaplace& L = *levels_[l].A;
    dims.insert(dims.end(), L.dims().begin(), L.dims().end());
    scales.push_back(L.scale());
    // per smoothing sweep as GpuLaplace::smooth counts it, the residual and the transfers
    bytes += double(L.size()) * 4.0 * (4 * (options_.preSmooth + options_.postSmooth) + 2 * L.dimension() + 10);
  }
  setUniform(p, "levels", count);
  glUniform3iv(p.uniform("dimsOf"), count, dims.data());
  glUniform1iv(p.uniform("offsetOf"), count, offsets_.data());
  setUniformDoubles(p, "scaleOf", scales.data(), count);
  setUniformBools(p, "periodic", A.periodic());
  setUniform(p, "preSmooth", options_.preSmooth);
  setUniform(p, "postSmooth", options_.postSmooth);
  const Level& T = levels_[tail_];
  T.x.bind(0);
  T.b.bind(1);
  T.r.bind(2);
  for (int a = 0; a < 3; ++a) tailW_[size_t(a < A.dimension() ? a : 0)].bind(3 + a);
  tailDiag_.bind(6);
  tailC_.bind(7);
  dense_.bind(8);
  countGpuTraffic(bytes);
  dispatchGroups(1, 1);
  storageBarrier();
}

void GpuMultigrid::smooth(Level& L, bool reverse, int sweeps, bool skipFirst, bool skipLast) {
  for (int s = 0; s < sweeps; ++s) {
    if (L.A->mixesColours()) {  // damped Jacobi, r as the other buffer
      L.A->jacobi(L.b, L.x, &L.r, L.A->dimension() == 3 ? 6.0f / 7.0f : 0.8f);
      std::swap(L.x, L.r);
      continue;
    }
    if (!(skipFirst && s == 0)) L.A->smooth(L.b, &L.x, reverse ? 1 : 0);
    if (!(skipLast && s == sweeps - 1)) L.A->smooth(L.b, &L.x, reverse ? 0 : 1);
  }
}

void GpuMultigrid::sweepBand(Level& L, bool reverse) {
  if (!L.band.id()) return;
  for (int s = 0; s < options_.bandSweeps; ++s)
    for (int q = 0; q < 2; ++q) {
      const int colour = reverse ? 1 - q : q;
      L.A->smoothCells(L.b, &L.x, L.band, colour == 0 ? 0 : L.bandCount[0], L.bandCount[size_t(colour)]);
    }
}

bool GpuMultigrid::sweepsFused() const {
  const GpuLaplace& A = *levels_[0].A;
  return levels_.size() > 1 && tail_ > 0 && !A.mixesColours() && options_.preSmooth > 0 && options_.postSmooth > 0;
}

void GpuMultigrid::cycle(size_t l) {
  if (l == tail_) return runTail();
  Level& L = levels_[l];
  const int dim = L.A->dimension();
  if (l + 1 == levels_.size()) {
    if (dense_.id()) {
      const ComputeProgram& p = useProgram("multigrid.comp", fmt::format("#define DIM {}\n#define MODE_DENSE", dim));
      setUniform(p, "n", int(L.A->size()));
      L.b.bind(0);
      L.x.bind(1);
      L.x.bind(2);
      L.A->diag().bind(3);
      dense_.bind(4);
      dispatchFlat(L.A->size(), 4.0 * double(L.A->size()) + 8.0);  // a row of the inverse, x
      storageBarrier();
    } else {
      L.x.zero();
      smooth(L, false, kCoarseSweeps);
      smooth(L, true, kCoarseSweeps);
    }
    return;
  }
  Level& C = levels_[l + 1];
  // (the finest level's first and last colours: in apply()'s conversions)
  const bool fused = l == 0 && sweepsFused();
  if (!fused) L.x.zero();
  smooth(L, false, options_.preSmooth, fused, false);
  sweepBand(L, false);
  auto transfer = [&](TransferMode mode, const GpuBuffer& fine, const GpuBuffer& coarse, const GpuBuffer& fineX,
                      const GpuBuffer& diag, size_t samples) {
    const ComputeProgram& p =
        useProgram("multigrid.comp", fmt::format("#define DIM {}\n#define {}", dim, define(mode)));
    setUniform(p, "fd", L.A->dims());
    setUniform(p, "cd", C.A->dims());
    setUniformBools(p, "periodic", L.A->periodic());
    fine.bind(0);
    coarse.bind(1);
    fineX.bind(2);
    diag.bind(3);
    fine.bind(4);
    const bool restriction = mode == TransferMode::Restrict;
    if (restriction) {  // the fine residual made in place: the fine level's b and system
      setUniform(p, "fineScale", L.A->scale());
      L.b.bind(5);
      for (int a = 0; a < 3; ++a) L.A->weights(a < dim ? a : 0).bind(6 + a);
      L.A->diag().bind(9);
      L.A->cBuffer().bind(10);
    }
    // restrict: the fine level's x, b, face weights, c and diag once (2^D fine
    // cells a coarse one), b, diag; prolong: x read and written, diag
    dispatchFlat(samples, restriction ? 4.0 * (dim + 4) * (1 << dim) + 8.0 : 12.0);
    storageBarrier();
  };
  transfer(TransferMode::Restrict, L.b, C.b, L.x, C.A->diag(), C.A->size());
  cycle(l + 1);
  transfer(TransferMode::Prolong, L.b, C.x, L.x, L.A->diag(), L.A->size());  // (fine unread)
  sweepBand(L, true);
  smooth(L, true, options_.postSmooth, false, fused);
}

void GpuMultigrid::apply(const GpuBuffer& r, GpuBuffer* z, const GpuBuffer& scalars, int slot, FusedDot rz) {
  Level& L = levels_[0];
  const size_t n = L.A->size();
  // To float with r . r's final pass, back with r . z's partial one; with
  // the finest level's first pre-smoothing colour and last post-smoothing one.
  const bool fused = sweepsFused();
  auto convert = [&](VectorOp op, const GpuBuffer& in, const GpuBuffer& out) {
    const bool back = op == VectorOp::FromFloat;
    const ComputeProgram& p = useProgram("vector_ops.comp",
                                         std::string("#define ") + define(op) + "\n#define DOT_PARTIAL" +
                                             (!fused ? ""
                                                     : fmt::format("\n#define DIM {}\n#define {}", L.A->dimension(),
                                                                   back ? "SWEEP_LAST" : "SWEEP_FIRST")),
                                         L.A->precision());
    if (fused) {
      setUniform(p, "levelDims", L.A->dims());
      setUniform(p, "levelScale", L.A->scale());
      if (back) {
        for (int a = 0; a < 3; ++a) L.A->weights(a < L.A->dimension() ? a : 0).bind(11 + a);
        L.b.bind(14);
      } else {
        L.x.bind(10);
      }
      // the sweep's update on half the cells (GpuLaplace::smooth's count)
      countGpuTraffic(0.5 * double(n) * 4.0 * (back ? 3 + L.A->dimension() + 2 : 2));
    }
    setUniform(p, "n", int(n));
    setUniform(p, "slots", std::array<int, 4>{slot, rz.slot, 0, 0});
    in.bind(0);
    out.bind(1);
    r.bind(2);
    in.bind(3);
    (back ? L.x : L.b).bind(4);
    L.A->diag().bind(5);
    scalars.bind(6);
    rz.partials->bind(8);
    in.bind(9);
    const double real = double(L.A->precision() == GpuPrecision::Float ? 4 : 8);  // r, z in; z out; f
    countGpuTraffic(double(n) * (back ? 2 * real + 4 : real + 4));
    dispatchGroups(GpuReduction::groups(n), 1);
    storageBarrier();
  };
  convert(VectorOp::ToFloat, r, r);
  cycle(0);
  convert(VectorOp::FromFloat, *z, *z);
}

template GpuMultigrid::GpuMultigrid(const Multigrid<2>&, const GpuLaplace&, const MultigridOptions&, size_t);
template GpuMultigrid::GpuMultigrid(const Multigrid<3>&, const GpuLaplace&, const MultigridOptions&, size_t);
template void GpuMultigrid::update(const Multigrid<2>&);
template void GpuMultigrid::update(const Multigrid<3>&);

}  // namespace morphoflow
