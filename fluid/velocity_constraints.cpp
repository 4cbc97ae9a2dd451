#include "fluid/velocity_constraints.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/parallel.h"

namespace morphoflow {

template <int D>
VelocityConstraints<D>::VelocityConstraints(const IVec<D>& c, double hh, const DomainBoundaries& b,
                                            const Grid<uint8_t, D>& s)
    : VelocityConstraints(c, hh, b, s, s, CutSurface()) {}

template <int D>
VelocityConstraints<D>::VelocityConstraints(const IVec<D>& c, double hh, const DomainBoundaries& b,
                                            const Grid<uint8_t, D>& s, const Grid<uint8_t, D>& voxel,
                                            const CutSurface& cutSurface, const CutSurface& solidBodies)
    : cells(c), h(hh), boundaries(b), solid(s), cut(cutSurface), bodies(solidBodies) {
  for (int a = 0; a < D; ++a) {
    IVec<D> fd = cells + unitVector<D>(a);
    fixed[a] = Grid<uint8_t, D>(fd, 0);
    open[a] = RowField<D>(fd, 1.0f);
    std::vector<float> value(fixed[a].size(), 0.0f);
    forEachCell<D>(fd, [&](const IVec<D>& k, size_t i) { open[a].at(i) = constrainFace(a, k, i, voxel, &value[i]); });
    open[a].compact();
    listFixed(a, value);
  }
  if (bodies.moving()) computeSolidFlux(IVec<D>(0), cells);
}

template <int D>
void VelocityConstraints<D>::move(const Grid<uint8_t, D>& s, const Grid<uint8_t, D>& voxel,
                                  const CutSurface& cutSurface, const CutSurface& solidBodies, const IVec<D>& lo,
                                  const IVec<D>& hi) {
  solid = s;
  cut = cutSurface;
  bodies = solidBodies;
  parallelTasks(size_t(D), [&](size_t axis) {  // (each grid's faces are its own)
    const int a = int(axis);
    // The faces of the cells [lo, hi): their rows of the open fractions
    // written again, and their prescribed faces listed again.
    const IVec<D> flo = lo, fhi = hi + unitVector<D>(a);
    const IVec<D>& fd = fixed[a].dims();
    const std::vector<size_t> rows = rowsOf<D>(fd, flo, fhi);
    std::vector<std::vector<std::pair<size_t, float>>> held(rows.size());
    rewriteRows<D, 1>({&open[a]}, rows, [&](size_t r, const std::array<float*, 1>& o) {
      const size_t k = size_t(std::lower_bound(rows.begin(), rows.end(), r) - rows.begin());
      IVec<D> c = fixed[a].coord(r * size_t(fd[0]));
      RowReach along{flo[0], 0.0};
      for (c[0] = flo[0]; c[0] < fhi[0]; ++c[0]) {
        const size_t i = fixed[a].index(c);
        float value = 0.0f;
        fixed[a][i] = 0;
        o[0][c[0]] = constrainFace(a, c, i, voxel, &value, &along);
        if (fixed[a][i]) held[k].emplace_back(i, value);
      }
    });
    relistFixed(a, rows, flo[0], fhi[0], held);
  });
  if (solidFlux.empty()) solidFlux.assign(solid.size(), 0.0);
  if (bodies.moving()) computeSolidFlux(lo, hi);
}

// Grid a's prescribed faces: the list less the faces x in [xlo, xhi) of
// `rows`, merged with `held`, theirs row by row (both ascending).
template <int D>
void VelocityConstraints<D>::relistFixed(int a, const std::vector<size_t>& rows, int xlo, int xhi,
                                         const std::vector<std::vector<std::pair<size_t, float>>>& held) {
  const size_t nx = size_t(fixed[a].dims()[0]);
  std::vector<uint8_t> inRows(fixed[a].size() / nx, 0);
  for (size_t r : rows) inRows[r] = 1;
  std::vector<size_t> faces;
  std::vector<float> values;
  size_t next = 0, q = 0;  // the region's next row, and its next face
  auto takeRegionUpTo = [&](size_t limit) {
    for (; next < held.size(); ++next, q = 0)
      for (; q < held[next].size(); ++q) {
        if (held[next][q].first >= limit) return;
        faces.push_back(held[next][q].first);
        values.push_back(held[next][q].second);
      }
  };
  for (size_t j = 0; j < fixedFaces[a].size(); ++j) {
    const size_t i = fixedFaces[a][j], x = i % nx;
    if (inRows[i / nx] && int(x) >= xlo && int(x) < xhi) continue;
    takeRegionUpTo(i);
    faces.push_back(i);
    values.push_back(fixedValues[a][j]);
  }
  takeRegionUpTo(SIZE_MAX);
  fixedFaces[a].swap(faces);
  fixedValues[a].swap(values);
}

template <int D>
double VelocityConstraints<D>::centreDistance(int a, const IVec<D>& k, RowReach* along) const {
  if (along && k[0] < along->until) return along->side;
  const double d = faceCentreDistance<D>(cut, a, k, h);
  if (!along || !cut.lipschitz()) return d;
  // The faces j further along lie at least |d| - j h from the surface:
  // beyond their reach (and a margin for rounding) while j h < far.
  const double far = std::abs(d) - faceReach(D, h) - 1e-9 * h;
  if (far > h) {
    along->until = k[0] + int(std::ceil(std::min(far / h, 1e6)));  // (faces k + 1 .. until - 1)
    along->side = std::copysign(std::numeric_limits<double>::infinity(), d);
  }
  return d;
}

// Face k (index i) of grid a: held by a wall, an inflow or a solid, and
// its open fraction.
template <int D>
float VelocityConstraints<D>::constrainFace(int a, const IVec<D>& k, size_t i, const Grid<uint8_t, D>& voxel,
                                            float* value, RowReach* along) {
  bool boundary = !boundaries.periodic(a) && (k[a] == 0 || k[a] == cells[a]);
  if (boundary) {
    bool high = k[a] == cells[a];
    const DomainSide& side = boundaries.side(a, high);
    if (side.kind == BoundaryKind::Wall) {
      fixed[a][i] = 1;
    } else if (side.kind == BoundaryKind::Inflow) {
      fixed[a][i] = 1;
      double speed = inflowSpeed(a, Layout<D>::face(a, h, cells, periodic()).toWorld(k));
      *value = float(high ? -speed : speed);
    }
  }
  // A face touching a staircase solid cell, or wholly inside a cut
  // obstacle, is held at the obstacle's velocity.
  IVec<D> lo = k - unitVector<D>(a);
  if (boundaries.periodic(a) && lo[a] < 0) lo[a] += cells[a];
  IVec<D> hi = k;
  if (boundaries.periodic(a) && hi[a] >= cells[a]) hi[a] -= cells[a];
  bool solidLo = lo[a] >= 0 && voxel(lo), solidHi = hi[a] < cells[a] && voxel(hi);
  IVec<D> same = k;  // on a periodic axis face n is face 0
  if (boundaries.periodic(a) && same[a] == cells[a]) same[a] = 0;
  float o = 1.0f;
  if (solidLo || solidHi) {
    o = 0.0f;
  } else if (!cut.empty()) {  // (the row's faces follow one another but for face n on a periodic x)
    o = openFractionFrom<D>(cut, a, same, h, centreDistance(a, same, same == k ? along : nullptr));
  }
  if (o == 0.0f) {
    fixed[a][i] = 1;
    *value = bodies.moving() ? float(bodies.velocity(facePosition(a, k).data(), a)) : 0.0f;
  }
  return o;
}

template <int D>
void VelocityConstraints<D>::listFixed(int a, const std::vector<float>& value) {
  fixedFaces[a].clear();
  fixedValues[a].clear();
  for (size_t i = 0; i < fixed[a].size(); ++i)
    if (fixed[a][i]) {
      fixedFaces[a].push_back(i);
      fixedValues[a].push_back(value[i]);
    }
}

// The moving solid's flux through the closed parts of the faces of the cells [lo, hi)
// (0 in a cell closed on every side), row by row as the divergence reads the faces.
template <int D>
void VelocityConstraints<D>::computeSolidFlux(const IVec<D>& lo, const IVec<D>& hi) {
  if (solidFlux.empty()) solidFlux.assign(solid.size(), 0.0);
  const std::vector<size_t> rows = rowsOf<D>(cells, lo, hi);
  const size_t nx = size_t(cells[0]);
  parallelFor(rows.size(), [&](size_t q) {
    IVec<D> k = latticeCoord<D>(cells, rows[q] * nx);
    std::array<const float*, D> below, above;  // grid a's faces k_a and k_a + 1 of the row's cells
    for (int a = 0; a < D; ++a) {
      const size_t fnx = size_t(fixed[a].dims()[0]);
      below[size_t(a)] = open[a].row(fixed[a].index(k) / fnx);
      above[size_t(a)] = a == 0 ? below[0] + 1 : open[a].row(fixed[a].index(k + unitVector<D>(a)) / fnx);
    }
    for (k[0] = lo[0]; k[0] < hi[0]; ++k[0]) {
      const size_t x = size_t(k[0]);
      bool fluid = false;  // (a cell whose faces are all closed holds no fluid, and no pressure: no flux)
      for (int a = 0; a < D; ++a) fluid = fluid || below[size_t(a)][x] > 0.0f || above[size_t(a)][x] > 0.0f;
      double flux = 0.0;
      for (int a = 0; a < D && fluid; ++a)
        for (int side = 0; side < 2; ++side) {
          const double closed = 1.0 - double((side ? above : below)[size_t(a)][x]);
          if (closed > 0.0)
            flux += (side ? closed : -closed) *
                    bodies.velocity(facePosition(a, k + (side ? unitVector<D>(a) : IVec<D>(0))).data(), a);
        }
      solidFlux[solid.index(k)] = flux;
    }
  });
}

template <int D>
std::array<bool, D> VelocityConstraints<D>::periodic() const {
  std::array<bool, D> p{};
  for (int a = 0; a < D; ++a) p[size_t(a)] = boundaries.periodic(a);
  return p;
}

template <int D>
double VelocityConstraints<D>::inflowSpeed(int axis, const Vec<D>& x) const {
  double u = boundaries.inflowMeanVelocity;
  if (boundaries.profile == InflowProfile::Uniform) return u;
  // Plane Poiseuille across each transverse axis bounded by walls: the
  // profile 4 s (1 - s) has mean 2/3, so the peak is 1.5 times the mean.
  for (int b = 0; b < D; ++b) {
    if (b == axis || boundaries.periodic(b)) continue;
    double s = x[b] / (cells[b] * h);
    u *= 1.5 * 4.0 * s * (1.0 - s);
  }
  return u;
}

template <int D>
std::array<double, 3> VelocityConstraints<D>::facePosition(int a, const IVec<D>& k) const {
  std::array<double, 3> x{0, 0, 0};  // (Layout::face's toWorld: offset 0 along a, 1/2 across)
  for (int b = 0; b < D; ++b) x[size_t(b)] = (double(k[b]) + (b == a ? 0.0 : 0.5)) * h;
  return x;
}

template <int D>
void VelocityConstraints<D>::apply(MacVelocity<D>* u) const {
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const std::vector<float>& v = fixedValues[a];
    const std::vector<size_t>& faces = fixedFaces[a];
    parallelFor(faces.size(), [&](size_t k) { g[faces[k]] = v[k]; }, 8192);
    if (boundaries.periodic(a)) {  // the layer k_a = n_a only
      const size_t stride = g.stride(a);
      IVec<D> layer = g.dims();
      layer[a] = 1;
      forEachCell<D>(layer, [&](const IVec<D>& k, size_t) {
        IVec<D> top = k;
        top[a] = cells[a];
        const size_t i = g.index(top);
        g[i] = g[i - stride * size_t(cells[a])];
      });
    }
  }
}

template <int D>
float VelocityConstraints<D>::prescribed(int a, size_t i) const {
  const std::vector<size_t>& faces = fixedFaces[a];
  auto it = std::lower_bound(faces.begin(), faces.end(), i);
  return it != faces.end() && *it == i ? fixedValues[a][size_t(it - faces.begin())] : 0.0f;
}

template <int D>
std::vector<float> VelocityConstraints<D>::prescribedGrid(int a) const {
  std::vector<float> v(fixed[a].size(), 0.0f);
  for (size_t k = 0; k < fixedFaces[a].size(); ++k) v[fixedFaces[a][k]] = fixedValues[a][k];
  return v;
}

template struct VelocityConstraints<2>;
template struct VelocityConstraints<3>;

}  // namespace morphoflow
