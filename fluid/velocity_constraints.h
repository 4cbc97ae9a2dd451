// Which velocity faces are prescribed (walls, inflow, solid obstacles) and to
// what value; the tangential wall velocities that no-slip ghosts reflect;
// the open fraction of every face (fluid/cut_cells.h). Built once per scene
// from the domain sides, the solid masks and the cut obstacles' surface.
#pragma once

#include <array>
#include <vector>

#include "core/mac_velocity.h"
#include "core/row_field.h"
#include "fluid/cut_cells.h"
#include "fluid/domain_boundary.h"

namespace morphoflow {

template <int D>
struct VelocityConstraints {
  IVec<D> cells{0};
  double h = 1.0;
  DomainBoundaries boundaries;
  Grid<uint8_t, D> solid;                   // cell flags: the centre lies inside an obstacle
  std::array<Grid<uint8_t, D>, D> fixed;    // per face grid: 1 = prescribed
  // Per face grid, the face's open fraction: 0 on a face of a staircase
  // (voxel) solid cell and on a face wholly inside a cut obstacle, the
  // fluid part of a face a cut obstacle crosses, 1 elsewhere (the domain's
  // sides too). The pressure projection weighs the faces by it.
  std::array<RowField<D>, D> open;
  CutSurface cut;  // the cut obstacles' surface (empty: none)
  // Every obstacle with its motion: the solid's velocity where one moves.
  CutSurface bodies;
  // With a moving obstacle, per cell: the flux the solid's velocity carries
  // through the closed part of its faces, times h^{1-D} (Batty et al. 2007
  // with u_solid: a face's flux is open u + (1 - open) u_solid . n); the
  // projection's divergence adds it. Empty when nothing moves.
  std::vector<double> solidFlux;
  // The indices of each grid's prescribed faces, ascending, and their
  // values: apply() visits these only, not the whole grid (a cavity
  // prescribes about 1 face in 20 at 128^3, and apply() runs several times
  // a step), and no grid of values is kept.
  std::array<std::vector<size_t>, D> fixedFaces;
  std::array<std::vector<float>, D> fixedValues;

  VelocityConstraints() = default;
  // `voxel`: the cells of the staircase obstacles (their faces are
  // prescribed); `cut`: the surface of the others. Without them every solid
  // cell is a staircase one.
  VelocityConstraints(const IVec<D>& cells, double h, const DomainBoundaries& b, const Grid<uint8_t, D>& solid);
  // `bodies`: every obstacle with its motion (fluid/obstacle_motion.h);
  // faces inside a moving solid are held at its velocity.
  VelocityConstraints(const IVec<D>& cells, double h, const DomainBoundaries& b, const Grid<uint8_t, D>& solid,
                      const Grid<uint8_t, D>& voxel, const CutSurface& cut, const CutSurface& bodies = {});

  std::array<bool, D> periodic() const;
  // Sets every prescribed face and copies face 0 onto face n on periodic axes.
  void apply(MacVelocity<D>* u) const;
  // The prescribed value of face i of grid a (0 where none is prescribed).
  float prescribed(int a, size_t i) const;
  // All of grid a's prescribed values (0 elsewhere), as one vector.
  std::vector<float> prescribedGrid(int a) const;
  // Inflow normal speed (into the domain) at a position on the inflow side.
  double inflowSpeed(int axis, const Vec<D>& x) const;
  // The world position of face k of grid a (x, y, z; 0 beyond D).
  std::array<double, 3> facePosition(int a, const IVec<D>& k) const;

  // The obstacles moved within the cells [lo, hi): the new solid cells,
  // surfaces and motions; only the faces of those cells are recomputed.
  void move(const Grid<uint8_t, D>& solid, const Grid<uint8_t, D>& voxel, const CutSurface& cut,
            const CutSurface& bodies, const IVec<D>& lo, const IVec<D>& hi);

 private:
  // Along a row of faces (rising x), what the last cut distance found
  // tells of the next faces: those before `until` lie farther than their
  // reach from a Lipschitz surface (CutSurface::lipschitz()), on the side
  // of `side` (an infinity of that sign, which their open fraction reads
  // as their centre's distance).
  struct RowReach {
    int until = 0;
    double side = 0.0;
  };
  // Face k (index i) of grid a: its fixed flag and *value set, its open
  // fraction returned; `along`, when given, the row's faces so far.
  float constrainFace(int a, const IVec<D>& k, size_t i, const Grid<uint8_t, D>& voxel, float* value,
                      RowReach* along = nullptr);
  // The cut distance at the centre of face k of grid a, or where `along`
  // knows the face wholly on one side, its side (and `along` updated).
  double centreDistance(int a, const IVec<D>& k, RowReach* along) const;
  void listFixed(int a, const std::vector<float>& value);
  void relistFixed(int a, const std::vector<size_t>& rows, int xlo, int xhi,
                   const std::vector<std::vector<std::pair<size_t, float>>>& held);
  void computeSolidFlux(const IVec<D>& lo, const IVec<D>& hi);
};

}  // namespace morphoflow
