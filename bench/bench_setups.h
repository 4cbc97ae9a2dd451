// The benchmark suites' shared cases: the lid-driven cavity and Pearson's
// Gray-Scott start, so `fluid`, `rd` and `coupling` time the same problems.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "bench/bench_timing.h"
#include "core/parallel.h"
#include "core/random.h"
#include "fluid/fluid_settings.h"
#include "rd/rd_solver.h"

namespace morphoflow {

// Unit cavity at Re = 100 (unit lid speed), pressure to 1e-6.
template <int D>
FluidSettings benchCavity(int n) {
  FluidSettings s;
  s.resolution.assign(D, n);
  s.size.assign(D, 1.0);
  s.viscosity = 1.0 / 100.0;  // Re = 100 with a unit lid
  s.boundaries.sides[3].wallVelocity = {1.0, 0.0, 0.0};
  s.pressureTolerance = 1e-6;
  return s;
}

// What the cavity holds: nothing, smoke, or a cut sphere (circle) of
// radius 0.15 at rest at the centre or circling it at radius 0.2 (a
// moving obstacle rebuilds its cut cells and the systems every step).
enum class BenchContent { Plain, Smoke, BodyAtRest, BodyMoving };
inline const char* contentName(BenchContent c) {
  const char* names[] = {"-", "smoke", "body at rest", "body moving"};
  return names[int(c)];
}

// The cavity with nothing, or with the body at rest or moving (not smoke: fluid_bench.cpp's).
template <int D>
FluidSettings benchCavityWith(int n, BenchContent content) {
  FluidSettings s = benchCavity<D>(n);
  if (content != BenchContent::BodyAtRest && content != BenchContent::BodyMoving) return s;
  ObstacleSpec body;
  body.shape = ObstacleShape::Sphere;
  body.center = {0.5, 0.5, 0.5};
  body.radius = 0.15;
  if (content == BenchContent::BodyMoving) {
    body.motion = {"0.5 + 0.2 * cos(t)", "0.5 + 0.2 * sin(t)"};
    if (D == 3) body.motion.push_back("0.5");
  } else {
    body.center = {0.7, 0.5, 0.5};  // where the moving one starts
  }
  s.obstacles = {body};
  return s;
}

// The runs of the fluid suites: each case plain, then (3D, with `smoke`)
// with smoke, and 3D and 2D 512^2 with the body at rest and moving.
inline std::vector<std::pair<BenchCase, BenchContent>> fluidBenchRuns(const std::vector<BenchCase>& cases, bool smoke) {
  std::vector<std::pair<BenchCase, BenchContent>> runs;
  for (BenchCase c : cases) {
    runs.push_back({c, BenchContent::Plain});
    if (smoke && c.dim == 3) runs.push_back({c, BenchContent::Smoke});
    if (c.dim == 3 || c.n == 512)
      for (BenchContent b : {BenchContent::BodyAtRest, BenchContent::BodyMoving}) runs.push_back({c, b});
  }
  return runs;
}

// Pearson's Gray-Scott (F = 0.04, k = 0.06) on n^D cells of size `cell`,
// diffusion rates 0.2 and 0.1 cell^2 per unit time.
template <int D>
RDSettings benchGrayScott(int n, double cell, RDIntegrator integrator) {
  RDSettings s;
  s.model = "gray-scott";
  s.resolution.assign(D, n);
  s.size.assign(D, n * cell);
  s.diffusion = {0.2 * cell * cell, 0.1 * cell * cell};
  s.integrator = integrator;
  return s;
}

// Pearson's start: u = 1, v = 0, a perturbed central square (u, v) = (1/2, 1/4).
template <int D>
void pearsonStart(RDSolver<D>* rd) {
  const int n = rd->cells()[0];
  forEachCell<D>(rd->cells(), [&](const IVec<D>& k, size_t i) {
    bool inside = true;
    for (int a = 0; a < D; ++a) inside &= std::abs((k[a] + 0.5) / n - 0.5) < 0.1;
    rd->field(0)[i] = (inside ? 0.5 : 1.0) + 0.01 * (uniform01(1, 0, i) - 0.5);
    rd->field(1)[i] = (inside ? 0.25 : 0.0) + 0.01 * (uniform01(1, 1, i) - 0.5);
  });
}

}  // namespace morphoflow
