#include "core/mic0.h"

#include <cmath>

namespace morphoflow {

// Off-diagonal entry A(i, i + e_a) = -scale * w_a(i), or 0 across an edge.
template <int D>
MIC0Preconditioner<D>::MIC0Preconditioner(const LaplaceSystem<D>& A, double tau, double sigma)
    : A_(A), precon_(A.size(), 0.0), q_(A.size(), 0.0) {
  const RowField<D>& diag = A.diag;
  for (size_t i = 0; i < A.size(); ++i) {
    if (diag[i] <= 0) continue;
    IVec<D> c = diag.coord(i);
    double aii = diag[i];  // the factor is computed on A / scale
    double e = aii;
    for (int a = 0; a < D; ++a) {
      if (c[a] == 0) continue;
      size_t j = i - diag.stride(a);
      if (diag[j] <= 0) continue;
      double aij = -double(A.w[a][j]);  // A(j, j + e_a)
      double pj = precon_[j];
      e -= (aij * pj) * (aij * pj);
      // Modification: the fill-in dropped along the other axes of j.
      double other = 0.0;
      IVec<D> cj = diag.coord(j);
      for (int b = 0; b < D; ++b)
        if (b != a && cj[b] + 1 < diag.dim(b)) other += -double(A.w[b][j]);
      e -= tau * aij * other * pj * pj;
    }
    if (e < sigma * aii) e = aii;
    precon_[i] = 1.0 / std::sqrt(e);
  }
}

template <int D>
void MIC0Preconditioner<D>::apply(const Vector& r, Vector* zp) {
  Vector& z = *zp;
  z.resize(r.size());
  const RowField<D>& diag = A_.diag;
  const double inv = 1.0 / A_.scale;
  size_t stride[D];
  for (int a = 0; a < D; ++a) stride[a] = diag.stride(a);
  // Solve L q = r.
  IVec<D> c(0);
  for (size_t i = 0; i < r.size(); ++i) {
    if (diag[i] > 0) {
      double t = r[i] * inv;
      for (int a = 0; a < D; ++a) {
        if (c[a] == 0) continue;
        size_t j = i - stride[a];
        t += double(A_.w[a][j]) * precon_[j] * q_[j];
      }
      q_[i] = t * precon_[i];
    } else {
      q_[i] = 0.0;
    }
    for (int a = 0; a < D; ++a) {  // advance the coordinate
      if (++c[a] < diag.dim(a)) break;
      c[a] = 0;
    }
  }
  // Solve L^T z = q.
  c = diag.dims() - IVec<D>(1);
  for (size_t k = r.size(); k-- > 0;) {
    if (diag[k] > 0) {
      double t = q_[k];
      for (int a = 0; a < D; ++a) {
        if (c[a] + 1 >= diag.dim(a)) continue;
        t += double(A_.w[a][k]) * precon_[k] * z[k + stride[a]];
      }
      z[k] = t * precon_[k];
    } else {
      z[k] = 0.0;
    }
    for (int a = 0; a < D; ++a) {
      if (--c[a] >= 0) break;
      c[a] = diag.dim(a) - 1;
    }
  }
}

template class MIC0Preconditioner<2>;
template class MIC0Preconditioner<3>;

}  // namespace morphoflow
