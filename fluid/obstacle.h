// Solid obstacles: analytic shapes, or masks from an image or a signed
// distance field. Cells whose centre lies inside are solid (no-slip); the
// fluid sees a "cut" obstacle's own surface (fluid/cut_cells.h), a "voxel"
// one's staircase of solid cells.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

enum class ObstacleShape { Circle, Sphere, Box, Image, Sdf };
// How the fluid's pressure and viscosity meet the obstacle: at its surface
// through the open fractions of the cut faces (Batty, Bertails & Bridson
// 2007) and the distance to it (Gibou et al. 2002), or at the faces of the
// cells whose centre lies inside (the staircase).
enum class ObstacleBoundary { Cut, Voxel };

struct ObstacleSpec {
  ObstacleShape shape = ObstacleShape::Circle;
  std::array<double, 3> center{0.5, 0.5, 0.5};
  double radius = 0.1;                          // circle, sphere
  std::array<double, 3> halfSize{0.1, 0.1, 0.1};  // box
  // Image and Sdf: a 2D field (x fastest) stretched over the domain's x-y
  // extent (extruded along z in 3D). Image: solid where value > threshold;
  // Sdf: signed distance in world units, negative inside.
  int fieldWidth = 0, fieldHeight = 0;
  std::vector<float> field;
  double threshold = 0.5;
  bool invert = false;  // image: solid where value <= threshold
  ObstacleBoundary boundary = ObstacleBoundary::Cut;  // obstacles only (sources ignore it)
  // Obstacles only: the centre per axis as expressions in t, and the angles
  // (2D: one, about z; 3D: about x, y and z, applied x first) as
  // expressions in t (fluid/obstacle_motion.h). Empty: fixed.
  std::vector<std::string> motion, rotation;
  // Per axis: the domain is periodic there, and the shape wraps across it
  // (its nearest image counts).
  std::array<bool, 3> wrap{false, false, false};
  // The body's orientation now, row-major, body to world (placedAt() sets it).
  std::array<double, 9> orientation{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

// Signed distance (negative inside) of the obstacle at a world position.
double obstacleDistance(const ObstacleSpec& spec, const double* x, int dims, const double* domainSize);

// Solid flags (1 = solid) of the cells of a D-dim grid of cell size h.
template <int D>
Grid<uint8_t, D> solidMask(const std::vector<ObstacleSpec>& obstacles, const IVec<D>& cells, double h);

// How much of each cell the obstacles hold, from their distance d at its
// centre: clamp(1/2 - d / h, 0, 1), whose half level is their surface (a
// smooth picture of them; solidMask() is what the fluid sees).
template <int D>
Grid<float, D> solidOccupancy(const std::vector<ObstacleSpec>& obstacles, const IVec<D>& cells, double h);

}  // namespace morphoflow
