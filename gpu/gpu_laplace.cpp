#include "gpu/gpu_laplace.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

template <int D>
GpuLaplace::GpuLaplace(const LaplaceSystem<D>& A) : dim_(D), n_(A.size()) {
  for (int a = 0; a < D; ++a) {
    dims_[size_t(a)] = A.dims[a];
    periodic_[size_t(a)] = A.periodic[size_t(a)];
  }
  for (int a = 0; a < D; ++a) w_[size_t(a)] = GpuBuffer(n_ * sizeof(float));
  if (D == 2) w_[2] = GpuBuffer(sizeof(float));
  diag_ = GpuBuffer(n_ * sizeof(float));
  c_ = GpuBuffer(n_ * sizeof(float));
  update(A);
}

template <int D>
GpuLaplace::GpuLaplace(const AnisotropicSystem<D>& A) : GpuLaplace(A.axis) {
  update(A);
}

template <int D>
void GpuLaplace::update(const AnisotropicSystem<D>& A) {
  update(A.axis);
  hasCross_ = A.hasCross;
  if (!hasCross_) return;
  for (int p = 0; p < AnisotropicSystem<D>::kPlanes; ++p) {
    for (int k = 0; k < 2; ++k) {
      const std::vector<float>& v = (k == 0 ? A.up : A.down)[size_t(p)].values();
      GpuBuffer& b = cross_[size_t(2 * p + k)];
      if (b.bytes() != v.size() * sizeof(float)) b = GpuBuffer(v.size() * sizeof(float));
      b.upload(v);
    }
  }
}

template <int D>
void GpuLaplace::update(const LaplaceSystem<D>& A) {
  update(A, 0, A.size() / size_t(A.dims[0]));
}

template <int D>
void GpuLaplace::update(const LaplaceSystem<D>& A, size_t rowBegin, size_t rowEnd) {
  const size_t at = rowBegin * size_t(A.dims[0]) * sizeof(float);
  for (int a = 0; a < D; ++a) w_[size_t(a)].upload(A.w[a].expandedRows(rowBegin, rowEnd), at);
  diag_.upload(A.diag.expandedRows(rowBegin, rowEnd), at);
  c_.upload(A.c.expandedRows(rowBegin, rowEnd), at);
  scale_ = A.scale;
  singular_ = A.singular();
}

GpuBuffer& GpuLaplace::crossBuffer(int k) {
  if (!hasCross_) {
    for (int q = 0; q < (dim_ == 3 ? 6 : 2); ++q) {
      cross_[size_t(q)] = GpuBuffer(n_ * sizeof(float));
      cross_[size_t(q)].zero();
    }
    hasCross_ = true;
  }
  return cross_[size_t(k)];
}

void GpuLaplace::recomputeDiagonal() {
  const ComputeProgram& p = useProgram("laplace_build.comp", fmt::format("#define DIM {}\n#define MODE_DIAG", dim_));
  setUniform(p, "dims", dims_);
  for (int a = 0; a < 3; ++a) w_[size_t(a < dim_ ? a : 0)].bind(a);
  c_.bind(3);
  diag_.bind(4);
  dispatchFlat(n_, 4.0 * (dim_ + 2));
  storageBarrier();
}

void GpuLaplace::assignShifted(GpuLaplace& source, double k) {
  const ComputeProgram& p = useProgram("laplace_build.comp", fmt::format("#define DIM {}\n#define MODE_SHIFT", dim_));
  setUniform(p, "dims", dims_);
  setUniform(p, "k", k);
  for (int a = 0; a < 3; ++a) {
    w_[size_t(a < dim_ ? a : 0)].bind(a);
    source.w_[size_t(a < dim_ ? a : 0)].bind(5 + a);
  }
  c_.bind(3);
  diag_.bind(4);
  source.c_.bind(8);
  dispatchFlat(n_, 8.0 * (dim_ + 1));
  storageBarrier();
  if (source.hasCross_) {
    const int mixed = dim_ == 3 ? 6 : 2;
    const ComputeProgram& q = useProgram("laplace_build.comp", fmt::format("#define DIM {}\n#define CROSS", dim_));
    setUniform(q, "dims", dims_);
    setUniform(q, "k", k);
    for (int m = 0; m < mixed; ++m) {
      source.cross_[size_t(m)].bind(m);
      crossBuffer(m).bind(8 + m);
    }
    dispatchFlat(n_, 8.0 * mixed);
    storageBarrier();
  }
  recomputeDiagonal();
}

bool GpuLaplace::mixesColours() const {
  for (int a = 0; a < dim_; ++a)
    if (periodic_[size_t(a)] && dims_[size_t(a)] % 2 == 1) return true;
  return false;
}

void GpuLaplace::run(LaplaceMode mode, bool single, const GpuBuffer& x, const GpuBuffer* y, const GpuBuffer* b,
                     int colour, float omega, const FusedDot* dot, const PUpdate* pUpdate,
                     const ResidualExtras* extras) const {
  const bool cross = hasCross_ && !single && (mode == LaplaceMode::Apply || mode == LaplaceMode::Residual);
  const GpuPrecision real = single ? GpuPrecision::Float : real_, solution = single ? real : solution_;
  std::string defines = fmt::format("#define DIM {}\n#define {}", dim_, define(mode));
  const auto add = [&](bool on, const char* name) {
    if (on) defines += std::string("\n#define ") + name;
  };
  add(cross, "CROSS");
  add(extras && extras->bSum >= 0, "MEAN_FREE");
  add(dot, "DOT_PARTIAL");
  add(pUpdate, "P_UPDATE");
  add(pUpdate && pUpdate->first, "P_FIRST");
  const ComputeProgram& p = useProgram("laplace.comp", defines, real, solution);
  setUniform(p, "dims", dims_);
  setUniform(p, "scale", scale_);
  setUniform(p, "colour", colour);
  setUniform(p, "omega", omega);
  x.bind(0);
  (y ? *y : x).bind(1);
  (b ? *b : x).bind(2);
  for (int a = 0; a < 3; ++a) w_[size_t(a < dim_ ? a : 0)].bind(3 + a);
  diag_.bind(6);
  c_.bind(7);
  const int crossBuffers = cross ? (dim_ == 3 ? 6 : 2) : 0;
  for (int k = 0; k < crossBuffers; ++k) cross_[size_t(k)].bind(8 + k);
  // x and y (and b), the face weights, c and the diagonal (and the mixed
  // terms); a smoothing pass touches half the cells
  const double realSize = double(realBytes(real)), coefficients = 4.0 * (dim_ + 2 + crossBuffers);
  const double bytes = mode == LaplaceMode::Smooth ? 0.5 * (3 * realSize + coefficients)
                                                   : (y ? 2 : 1) * realSize + (b ? realSize : 0) + coefficients;
  if (pUpdate) {
    pUpdate->pNew->bind(8);
    pUpdate->scalars->bind(15);
    setUniform(p, "pSlots", pUpdate->slots);
  }
  if (dot && mode == LaplaceMode::Residual) {
    const ResidualExtras none;
    const ResidualExtras& e = extras ? *extras : none;
    glUniform4i(p.uniform("extra"), e.bb, e.rz, e.noRhs, e.xSum);
    glUniform2i(p.uniform("mean"), e.bSum, e.count);
    (e.scalars ? *e.scalars : x).bind(15);
    if (!cross) (e.z ? *e.z : x).bind(8);
    countGpuTraffic(double(n_) * realSize * ((e.rz >= 0 ? 1 : 0) + (e.noRhs >= 0 ? 1 : 0)));
  }
  if (dot) {
    setUniform(p, "slot", dot->slot);
    dot->partials->bind(14);
    countGpuTraffic(double(n_) * bytes);
    dispatchGroups(GpuReduction::groups(n_), 1);
  } else {
    dispatchFlat(n_, bytes);
  }
  storageBarrier();
}

void GpuLaplace::apply(const GpuBuffer& x, GpuBuffer* y) const {
  run(LaplaceMode::Apply, false, x, y, nullptr, 0, 0.0f);
}

void GpuLaplace::apply(const GpuBuffer& x, GpuBuffer* y, FusedDot dot) const {
  run(LaplaceMode::Apply, false, x, y, nullptr, 0, 0.0f, &dot);
}

void GpuLaplace::residual(const GpuBuffer& b, const GpuBuffer& x, GpuBuffer* r, FusedDot dot,
                          const ResidualExtras& extras) const {
  if ((extras.noRhs >= 0 || extras.bSum >= 0) && !extras.scalars)
    throw GpuError("the residual's b = 0 test and mean read the scalars");
  if (extras.rz >= 0 && (!extras.z || hasCross_))
    throw GpuError("the residual's diagonal preconditioner needs z and no mixed terms");
  if (extras.rz >= 0 && extras.xSum >= 0) throw GpuError("the residual sums r . z or x, not both");
  run(LaplaceMode::Residual, false, x, r, &b, 0, 0.0f, &dot, nullptr, &extras);
}

void GpuLaplace::applyUpdatingP(const GpuBuffer& p, const GpuBuffer& z, GpuBuffer* pNew, GpuBuffer* q, FusedDot pq,
                                const GpuBuffer& scalars, std::array<int, 4> slots, bool first) const {
  const PUpdate u{pNew, &scalars, slots, first};
  countGpuTraffic(double(n_) * double(realBytes(real_)));  // p' written (z is run's b)
  run(LaplaceMode::Apply, false, p, q, &z, 0, 0.0f, &pq, &u);
}

void GpuLaplace::smooth(const GpuBuffer& b, GpuBuffer* x, int colour) const {
  run(LaplaceMode::Smooth, true, *x, nullptr, &b, colour, 0.0f);
}

void GpuLaplace::smoothCells(const GpuBuffer& b, GpuBuffer* x, const GpuBuffer& cells, int first, int count) const {
  if (count == 0) return;
  const ComputeProgram& p = useProgram(
      "laplace.comp", fmt::format("#define DIM {}\n#define {}\n#define CELL_LIST", dim_, define(LaplaceMode::Smooth)),
      GpuPrecision::Float, GpuPrecision::Float);
  setUniform(p, "dims", dims_);
  setUniform(p, "scale", scale_);
  setUniform(p, "colour", -1);  // (the list's cells are of one colour)
  setUniform(p, "listFirst", first);
  setUniform(p, "listCount", count);
  x->bind(0);
  x->bind(1);
  b.bind(2);
  for (int a = 0; a < 3; ++a) w_[size_t(a < dim_ ? a : 0)].bind(3 + a);
  diag_.bind(6);
  c_.bind(7);
  cells.bind(8);
  // a cell's index, x, b, its neighbours' x and its coefficients
  dispatchFlat(size_t(count), 4.0 * (3 + 2 * dim_ + dim_ + 2));
  storageBarrier();
}

void GpuLaplace::jacobi(const GpuBuffer& b, const GpuBuffer& x, GpuBuffer* y, float omega) const {
  run(LaplaceMode::Jacobi, true, x, y, &b, 0, omega);
}

template GpuLaplace::GpuLaplace(const LaplaceSystem<2>&);
template GpuLaplace::GpuLaplace(const LaplaceSystem<3>&);
template void GpuLaplace::update(const LaplaceSystem<2>&);
template void GpuLaplace::update(const LaplaceSystem<3>&);
template void GpuLaplace::update(const LaplaceSystem<2>&, size_t, size_t);
template void GpuLaplace::update(const LaplaceSystem<3>&, size_t, size_t);
template GpuLaplace::GpuLaplace(const AnisotropicSystem<2>&);
template GpuLaplace::GpuLaplace(const AnisotropicSystem<3>&);
template void GpuLaplace::update(const AnisotropicSystem<2>&);
template void GpuLaplace::update(const AnisotropicSystem<3>&);

}  // namespace morphoflow
