#include "fluid/obstacle_placement.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "core/row_field.h"
#include "fluid/obstacle.h"

namespace morphoflow {

namespace {
// from's cells [lo, hi) written into *to (all of from where *to has another shape).
template <int D>
void copyBox(const Grid<uint8_t, D>& from, Grid<uint8_t, D>* to, const IVec<D>& lo, const IVec<D>& hi) {
  if (to->dims() != from.dims()) {
    *to = from;
    return;
  }
  const size_t nx = size_t(from.dims()[0]);
  for (size_t row : rowsOf<D>(from.dims(), lo, hi))
    std::copy(from.data() + row * nx + size_t(lo[0]), from.data() + row * nx + size_t(hi[0]),
              to->data() + row * nx + size_t(lo[0]));
}
}  // namespace

template <int D>
ObstaclePlacement<D>::ObstaclePlacement(const FluidSettings& s, const IVec<D>& cells, double h)
    : obstacles_(s.obstacles), boundaries_(s.boundaries), cells_(cells), h_(h), moves_(anyMoves(s.obstacles)) {}

// The obstacles where they are at time t (wrapping across periodic axes), with their motions.
template <int D>
std::vector<ObstacleSpec> ObstaclePlacement<D>::obstaclesAt(double t, std::vector<RigidMotion>* motions) const {
  std::vector<ObstacleSpec> placed = placedAt(obstacles_, D, t, motions);
  for (ObstacleSpec& o : placed)
    for (int a = 0; a < D; ++a) o.wrap[size_t(a)] = boundaries_.periodic(a);
  return placed;
}

template <int D>
VelocityConstraints<D> ObstaclePlacement<D>::constraintsAt(double t) {
  placed_ = obstaclesAt(t, &motions_);
  placedAt_ = t;
  std::vector<ObstacleSpec> voxel;  // the staircase obstacles; the others are cut
  for (const ObstacleSpec& o : placed_)
    if (o.boundary == ObstacleBoundary::Voxel) voxel.push_back(o);
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells_[a] * h_;
  if (moves_) voxel_ = solidMask<D>(voxel, cells_, h_);
  return VelocityConstraints<D>(cells_, h_, boundaries_, solidMask<D>(placed_, cells_, h_),
                                moves_ ? voxel_ : solidMask<D>(voxel, cells_, h_), CutSurface(placed_, D, size),
                                CutSurface(placed_, D, size, motions_, true));
}

// The cells [lo, hi) that hold the moving obstacles of `placed`, two cells
// more on every side, grown to hold what they held already; false when one
// has no bounds.
template <int D>
bool ObstaclePlacement<D>::movingCells(const std::vector<ObstacleSpec>& placed, IVec<D>* lo, IVec<D>* hi) const {
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells_[a] * h_;
  for (const ObstacleSpec& o : placed) {
    if (!movesAtAll(o)) continue;
    double blo[3], bhi[3];
    if (!obstacleBounds(o, D, size, blo, bhi)) return false;
    for (int a = 0; a < D; ++a) {
      int l = int(std::floor(blo[a] / h_)) - 2, u = int(std::ceil(bhi[a] / h_)) + 2;
      if (o.wrap[size_t(a)] && (l < 0 || u > cells_[a])) l = 0, u = cells_[a];  // across the seam: the whole axis
      (*lo)[a] = std::min((*lo)[a], std::clamp(l, 0, cells_[a]));
      (*hi)[a] = std::max((*hi)[a], std::clamp(u, 0, cells_[a]));
    }
  }
  return true;
}

template <int D>
bool ObstaclePlacement<D>::moveTo(double t, VelocityConstraints<D>* vc, IVec<D>* lo, IVec<D>* hi) {
  std::vector<RigidMotion> motions;
  std::vector<ObstacleSpec> placed = obstaclesAt(t, &motions);
  movedLo_ = movedHi_ = IVec<D>(0);
  *lo = cells_, *hi = IVec<D>(0);
  if (!movingCells(placed_, lo, hi) || !movingCells(placed, lo, hi)) {
    wasSolid_ = vc->solid;
    for (int a = 0; a < D; ++a) wasFixed_[size_t(a)] = vc->fixed[a];
    *vc = constraintsAt(t);  // (which places them itself)
    *lo = IVec<D>(0), *hi = cells_;
    movedLo_ = *lo, movedHi_ = *hi;
    return true;
  }
  placedAt_ = t;
  for (int a = 0; a < D; ++a)
    if ((*hi)[a] <= (*lo)[a]) {
      placed_ = std::move(placed);
      motions_ = std::move(motions);
      return false;
    }
  movedLo_ = *lo, movedHi_ = *hi;
  // The fill plans read what was there in the moved box alone.
  copyBox<D>(vc->solid, &wasSolid_, *lo, *hi);
  for (int a = 0; a < D; ++a) copyBox<D>(vc->fixed[a], &wasFixed_[size_t(a)], *lo, *hi + unitVector<D>(a));
  nowSolid_ = vc->solid;
  Grid<uint8_t, D>& solid = nowSolid_;
  std::vector<ObstacleSpec> voxel;
  for (const ObstacleSpec& o : placed)
    if (o.boundary == ObstacleBoundary::Voxel) voxel.push_back(o);
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells_[a] * h_;
  forEachCell<D>(*hi - *lo, [&](const IVec<D>& r, size_t) {
    const IVec<D> k = *lo + r;
    double x[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) x[a] = (k[a] + 0.5) * h_;
    auto inside = [&](const std::vector<ObstacleSpec>& list) {
      return std::any_of(list.begin(), list.end(),
                         [&](const ObstacleSpec& o) { return obstacleDistance(o, x, D, size) < 0.0; });
    };
    solid(k) = inside(placed) ? 1 : 0;
    voxel_(k) = inside(voxel) ? 1 : 0;
  });
  vc->move(solid, voxel_, CutSurface(placed, D, size), CutSurface(placed, D, size, motions, true), *lo, *hi);
  placed_ = std::move(placed);
  motions_ = std::move(motions);
  return true;
}

template <int D>
FillPlan ObstaclePlacement<D>::cellFill(const VelocityConstraints<D>& vc) const {
  return fillPlan<D>(wasSolid_, vc.solid, movedLo_, movedHi_);
}

template <int D>
FillPlan ObstaclePlacement<D>::faceFill(const VelocityConstraints<D>& vc, int a) const {
  return fillPlan<D>(wasFixed_[size_t(a)], vc.fixed[a], movedLo_, movedHi_ + unitVector<D>(a));
}

template class ObstaclePlacement<2>;
template class ObstaclePlacement<3>;

}  // namespace morphoflow
