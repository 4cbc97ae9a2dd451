#include "core/anisotropic_system.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

namespace {

template <int D>
IVec<D> unit(int a, int sign = 1) {
  IVec<D> e(0);
  e[a] = sign;
  return e;
}

// The four diagonal neighbours of a cell in plane p: +up, +down, -up, -down.
template <int D>
std::array<IVec<D>, 4> diagonalOffsets(int p) {
  const int a = AnisotropicSystem<D>::planeAxis(p, 0), b = AnisotropicSystem<D>::planeAxis(p, 1);
  IVec<D> up = unit<D>(a) + unit<D>(b), down = unit<D>(a) - unit<D>(b);
  return {up, down, -up, -down};
}

}  // namespace

template <int D>
AnisotropicSystem<D> AnisotropicSystem<D>::fromTensor(const IVec<D>& dims, const std::array<bool, D>& periodic,
                                                      double scale,
                                                      const std::array<const double*, kComponents>& sigma) {
  AnisotropicSystem<D> s(LaplaceSystem<D>(dims, periodic, scale));
  const size_t n = s.size();
  // A diagonal tensor (no mixed components anywhere) is a plain LaplaceSystem.
  for (int p = 0; p < kPlanes && !s.hasCross; ++p)
    s.hasCross = std::any_of(sigma[size_t(D + p)], sigma[size_t(D + p)] + n, [](double v) { return v != 0.0; });
  for (int p = 0; p < kPlanes && s.hasCross; ++p) {
    s.up[size_t(p)] = Grid<float, D>(dims, 0.0f);
    s.down[size_t(p)] = Grid<float, D>(dims, 0.0f);
  }
  forEachCell<D>(dims, [&](const IVec<D>& c, size_t i) {
    // Axis faces: sigma_aa at the face, the mean of its two cells (seed 001 eq. 17).
    for (int a = 0; a < D; ++a) {
      bool in = true;
      size_t j = shiftedIndex<D>(dims, periodic, c, unit<D>(a), &in);
      s.axis.w[a].at(i) = in ? float(0.5 * (sigma[size_t(a)][i] + sigma[size_t(a)][j])) : 0.0f;
    }
    // Mixed terms: the 2x2 block's two other cells (seed 004 eq. 17, second order).
    for (int p = 0; p < kPlanes && s.hasCross; ++p) {
      const int a = planeAxis(p, 0), b = planeAxis(p, 1);
      const double* sab = sigma[size_t(D + p)];
      bool inA = true, inUp = true, inDown = true;
      const size_t ia = shiftedIndex<D>(dims, periodic, c, unit<D>(a), &inA);
      const size_t ibUp = shiftedIndex<D>(dims, periodic, c, unit<D>(b), &inUp);
      const size_t ibDown = shiftedIndex<D>(dims, periodic, c, unit<D>(b, -1), &inDown);
      s.up[size_t(p)][i] = inA && inUp ? float(0.25 * (sab[ia] + sab[ibUp])) : 0.0f;
      s.down[size_t(p)][i] = inA && inDown ? float(-0.25 * (sab[ia] + sab[ibDown])) : 0.0f;
    }
  });
  s.axis.finalize();
  return s;
}

template <int D>
void AnisotropicSystem<D>::apply(const Vector& x, Vector* yp) const {
  yp->resize(x.size());
  axis.apply(x, yp);
  if (!hasCross) return;
  Vector& y = *yp;
  const IVec<D>& dims = axis.dims;
  const int nx = dims[0];
  const double sc = axis.scale;
  parallelForRows<D>(dims, [&](size_t row) {
    IVec<D> c(0);
    c[1] = int(row % size_t(dims[1]));
    if constexpr (D == 3) c[2] = int(row / size_t(dims[1]));
    const size_t base = row * size_t(nx);
    for (int p = 0; p < kPlanes; ++p) {
      const std::array<IVec<D>, 4> off = diagonalOffsets<D>(p);
      // Row of each neighbour (x shift applied per cell below); the couplings
      // of -up and -down live at the neighbour, those of +up and +down here.
      const double* xq[4];
      const float* kq[4];
      int ox[4];
      for (int n = 0; n < 4; ++n) {
        IVec<D> o = off[size_t(n)];
        ox[n] = o[0];
        o[0] = 0;
        bool in = true;
        size_t rb = shiftedIndex<D>(dims, axis.periodic, c, o, &in);
        xq[n] = x.data() + rb;
        const Grid<float, D>& k = (n % 2 == 0) ? up[size_t(p)] : down[size_t(p)];
        kq[n] = k.data() + (n < 2 ? base : rb);
      }
      for (int i = 0; i < nx; ++i) {
        const double xp = x[base + size_t(i)];
        double sum = 0.0;
        for (int n = 0; n < 4; ++n) {
          int j = i + ox[n];
          j = j < 0 ? j + nx : j >= nx ? j - nx : j;
          const float k = n < 2 ? kq[n][i] : kq[n][j];
          sum += double(k) * (xp - xq[n][j]);
        }
        y[base + size_t(i)] += sc * sum;
      }
    }
  });
}

template <int D>
double AnisotropicSystem<D>::residual(const Vector& b, const Vector& x, Vector* r) const {
  if (!hasCross) return axis.residual(b, x, r);
  apply(x, r);
  Vector& rr = *r;
  parallelFor(rr.size(), [&](size_t i) { rr[i] = axis.diag[i] > 0 ? b[i] - rr[i] : 0.0; }, 4096);
  return norm2(rr);
}

template <int D>
AnisotropicSystem<D> AnisotropicSystem<D>::shifted(double s) const {
  AnisotropicSystem<D> t = *this;
  t.axis.scale = 1.0;
  const double k = s * axis.scale;
  for (int a = 0; a < D; ++a) t.axis.w[a].transform([k](float v) { return float(double(v) * k); });
  t.axis.c.transform([k](float v) { return float(1.0 + k * double(v)); });
  t.axis.finalize();
  if (hasCross)
    for (int p = 0; p < kPlanes; ++p)
      for (size_t i = 0; i < size(); ++i) {
        t.up[size_t(p)][i] = float(double(up[size_t(p)][i]) * k);
        t.down[size_t(p)][i] = float(double(down[size_t(p)][i]) * k);
      }
  return t;
}

template <int D>
double AnisotropicSystem<D>::maxRowAbsSum() const {
  const IVec<D>& dims = axis.dims;
  Grid<double, D> sums(dims, 0.0);
  forEachCell<D>(dims, [&](const IVec<D>& c, size_t i) {
    double diag = axis.c[i], off = 0.0;
    for (int a = 0; a < D; ++a) {
      bool in = true;
      size_t lo = shiftedIndex<D>(dims, axis.periodic, c, unit<D>(a, -1), &in);
      const double wl = in ? axis.w[a][lo] : 0.0, wh = axis.w[a][i];
      diag += wl + wh;
      off += std::abs(wl) + std::abs(wh);
    }
    if (hasCross)
      for (int p = 0; p < kPlanes; ++p) {
        const std::array<IVec<D>, 4> o = diagonalOffsets<D>(p);
        bool in = true;
        const double k[4] = {up[size_t(p)][i], down[size_t(p)][i],
                             up[size_t(p)][shiftedIndex<D>(dims, axis.periodic, c, o[2], &in)],
                             down[size_t(p)][shiftedIndex<D>(dims, axis.periodic, c, o[3], &in)]};
        for (double v : k) {
          diag += v;
          off += std::abs(v);
        }
      }
    sums[i] = std::abs(diag) + off;
  });
  return deterministicMax(sums.size(), [&](size_t i) { return sums[i]; });
}

template struct AnisotropicSystem<2>;
template struct AnisotropicSystem<3>;

}  // namespace morphoflow
