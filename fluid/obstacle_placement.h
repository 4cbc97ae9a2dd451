// Where the obstacles are: the fluid's constraints (fluid/velocity_constraints.h)
// with every obstacle placed at a time, and their update as moving ones go
// (fluid/obstacle_motion.h). The geometry depends on the time alone, so the
// CPU solver and the GPU backend each keep one and place it at every step.
#pragma once

#include <array>
#include <vector>

#include "fluid/extrapolation.h"
#include "fluid/fluid_settings.h"
#include "fluid/obstacle_motion.h"
#include "fluid/velocity_constraints.h"

namespace morphoflow {

template <int D>
class ObstaclePlacement {
 public:
  ObstaclePlacement() = default;
  ObstaclePlacement(const FluidSettings& settings, const IVec<D>& cells, double h);
  // Whether an obstacle moves (obstacles.N.motion or rotation).
  bool moves() const { return moves_; }
  // The domain's sides and the obstacles at time t (placed there).
  VelocityConstraints<D> constraintsAt(double t);
  // *vc (this placement's) with the moving obstacles moved to time t,
  // recomputed in the cells [lo, hi) that held or hold one (set; the whole
  // grid when one has no bounds). False when none is in the domain, then
  // or now: nothing changed.
  bool moveTo(double t, VelocityConstraints<D>* vc, IVec<D>* lo, IVec<D>* hi);
  double time() const { return placedAt_; }  // the time they were placed for
  // The obstacles where they were last placed, and their motions then (index by index).
  const std::vector<ObstacleSpec>& placed() const { return placed_; }
  const std::vector<RigidMotion>& motions() const { return motions_; }
  // The fill plans of the last moveTo (fluid/extrapolation.h): the cells
  // and the faces of axis a it uncovered and covered in *vc.
  FillPlan cellFill(const VelocityConstraints<D>& vc) const;
  FillPlan faceFill(const VelocityConstraints<D>& vc, int a) const;

 private:
  std::vector<ObstacleSpec> obstaclesAt(double t, std::vector<RigidMotion>* motions) const;
  bool movingCells(const std::vector<ObstacleSpec>& placed, IVec<D>* lo, IVec<D>* hi) const;

  std::vector<ObstacleSpec> obstacles_;
  DomainBoundaries boundaries_;
  IVec<D> cells_{0};
  double h_ = 1.0;
  bool moves_ = false;
  std::vector<ObstacleSpec> placed_;  // the obstacles where they are now
  std::vector<RigidMotion> motions_;  // and their motions
  Grid<uint8_t, D> voxel_;            // the staircase obstacles' cells (when one moves)
  double placedAt_ = 0.0;
  // The flags before the last move, and the box it changed (storage kept from step to step).
  Grid<uint8_t, D> wasSolid_, nowSolid_;
  std::array<Grid<uint8_t, D>, D> wasFixed_;
  IVec<D> movedLo_{0}, movedHi_{0};
};

}  // namespace morphoflow
