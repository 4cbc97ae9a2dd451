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

  // Velocity vector at a world position (each component interpolated on its faces).
  Vec<D> sample(const Vec<D>& x) const {
    Vec<D> v;
    for (int a = 0; a < D; ++a) v[a] = sampleLinear(u_[a], layout_[a], x);
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

// One LinearSampler per component (for hot loops in cell units).
template <int D>
std::array<LinearSampler<D>, D> makeVelocitySamplers(const MacVelocity<D>& u) {
  if constexpr (D == 2)
    return {LinearSampler<2>(u[0], u.layout(0)), LinearSampler<2>(u[1], u.layout(1))};
  else
    return {LinearSampler<3>(u[0], u.layout(0)), LinearSampler<3>(u[1], u.layout(1)),
            LinearSampler<3>(u[2], u.layout(2))};
}

}  // namespace morphoflow
