// A scene's reaction-diffusion layer on an RDSolver: its initial state, its
// parameter maps, perturbations, fixed regions and anisotropy, coarse-to-fine
// growth, and a divergence check. Shared by the RD-only and coupled simulations.
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "rd/rd_solver.h"
#include "scenes/scene.h"

namespace morphoflow {

template <int D>
void initialState(const Scene& scene, RDSolver<D>* rd);
template <int D>
void applyScene(const Scene& scene, RDSolver<D>* rd);
// Throws NonFiniteError when a species is NaN, infinite or beyond float
// range, naming `where` (the step), `stage`, and for the explicit integrator its stable dt.
template <int D>
void checkFinite(const RDSolver<D>& rd, const std::string& where, const std::string& stage);
// "the explicit reaction-diffusion step", ...: the integrator's step, for messages.
std::string rdStage(const RDSettings& settings);
// Coarse-to-fine acceleration (seed 002, seed 000 sec. 6): grows the pattern
// on grids 2^L, ..., 2 times coarser over the same domain, each started from
// the previous one, and prolongates the last onto `rd`; false (rd untouched)
// when the scene asks for none. Each level's line goes to `log` and `report`.
// `advance` (when given) takes a coarse level's steps instead of its own
// step(): the GPU backend's (the level's state in, its state after out).
template <int D>
using CoarseAdvance = std::function<void(RDSolver<D>* level, long steps, double dt)>;
template <int D>
bool growCoarseToFine(const Scene& scene, RDSolver<D>* rd, const std::function<void(const std::string&)>& log,
                      nlohmann::json* report, const CoarseAdvance<D>& advance = {});
// A species as floats, for frames and dumps.
template <int D>
Grid<float, D> toFloat(const Grid<double, D>& src) {
  Grid<float, D> f(src.dims());
  for (size_t i = 0; i < f.size(); ++i) f[i] = float(src[i]);
  return f;
}

}  // namespace morphoflow
