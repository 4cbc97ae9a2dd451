// MacVelocity<D>: a MAC-staggered velocity field. Component a lives on the
// faces normal to axis a: dims = cells + e_a, sample k at (k + 0.5 - 0.5 e_a) h.
// On a periodic axis a, face n_a duplicates face 0.
#pragma once

#include <array>

#include "core/grid.h"
#include "core/linear_sampler.h"
#include "core/sampling.h"

namespace morphoflow {

template <int D>
class MacVelocity {
 public:
  MacVelocity() = default;
  MacVelocity(const IVec<D>& cells, double h, const std::array<bool, D>& periodic)
      : cells_(cells), h_(h), periodic_(periodic) {
    for (int a = 0; a < D; ++a) {
      u_[a] = Grid<float, D>(cells + unitVector<D>(a), 0.0f);
      layout_[a] = Layout<D>::face(a, h, cells, periodic);
    }
  }

  const IVec<D>& cells() const { return cells_; }
  double h() const { return h_; }
  const std::array<bool, D>& periodic() const { return periodic_; }
  Grid<float, D>& operator[](int a) { return u_[a]; }
  const Grid<float, D>& operator[](int a) const { return u_[a]; }
  const Layout<D>& layout(int a) const { return layout_[a]; }

  // Velocity vector at a world position (each component interpolated on its
  // faces): sampleLinear per component, with the axis stencils shared (along
  // axis b, component b's samples sit on faces and the others' at centres).
  Vec<D> sample(const Vec<D>& x) const {
    int f0[D], f1[D], c0[D], c1[D];
    double ft[D], ct[D];
    for (int b = 0; b < D; ++b) {
      const double g = x[b] / h_;  // Layout::toGrid, offset 0 (faces) or 0.5 (centres)
      detail::axisStencil(g - 0.0, cells_[b] + 1, periodic_[size_t(b)], cells_[b], &f0[b], &f1[b], &ft[b]);
      detail::axisStencil(g - 0.5, cells_[b], periodic_[size_t(b)], cells_[b], &c0[b], &c1[b], &ct[b]);
    }
    Vec<D> v;
    for (int a = 0; a < D; ++a) {
      int i0[D], i1[D];
      double t[D];
      for (int b = 0; b < D; ++b) {
        i0[b] = b == a ? f0[b] : c0[b];
        i1[b] = b == a ? f1[b] : c1[b];
        t[b] = b == a ? ft[b] : ct[b];
      }
      v[a] = interpolateStencil<float, D>(u_[a], i0, i1, t);
    }
    return v;
  }
  // Velocity at the centre of a cell (mean of the two faces per axis).
  Vec<D> atCell(const IVec<D>& c) const {
    Vec<D> v;
    for (int a = 0; a < D; ++a) v[a] = 0.5 * (double(u_[a](c)) + double(u_[a](c + unitVector<D>(a))));
    return v;
  }

 private:
  IVec<D> cells_{0};
  double h_ = 1.0;
  std::array<bool, D> periodic_{};
  std::array<Grid<float, D>, D> u_;
  std::array<Layout<D>, D> layout_;
};

// The velocity vector at a point, in cell units, for hot loops. Along each
// axis a component's samples sit either on faces (its own axis) or at cell
// centres (the others), so the D components share 2D axis taps instead of
// computing D^2.
template <int D>
struct MacSampler {
  const float* data[D];
  size_t stride[D][D];   // stride[a][b]: component a's distance between neighbours along b
  AxisSamples face[D];   // along axis b: the faces of component b
  AxisSamples centre[D]; // along axis b: the cell centres of the other components

  explicit MacSampler(const MacVelocity<D>& u) {
    for (int a = 0; a < D; ++a) {
      data[a] = u[a].data();
      size_t s = 1;
      for (int b = 0; b < D; ++b) {
        stride[a][b] = s;
        s *= size_t(u[a].dim(b));
      }
      const int cells = u.cells()[a];
      const bool periodic = u.periodic()[size_t(a)];
      face[a] = AxisSamples(cells + 1, cells, periodic, 0.0f);
      centre[a] = AxisSamples(cells, cells, periodic, 0.5f);
    }
  }

  void operator()(const float* p, float* v) const {
    AxisTap f[D], c[D];
    for (int b = 0; b < D; ++b) {
      f[b] = face[b].at(p[b]);
      c[b] = centre[b].at(p[b]);
    }
    for (int a = 0; a < D; ++a) {
      AxisTap t[D];
      for (int b = 0; b < D; ++b) t[b] = b == a ? f[b] : c[b];
      v[a] = interpolate<D>(data[a], stride[a], t);
    }
  }
};

}  // namespace morphoflow
