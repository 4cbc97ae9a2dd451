// `morphoflow run` for reaction-diffusion-only scenes (no [fluid]).
#pragma once

#include <string>

#include "app/run_options.h"
#include "rd/rd_solver.h"
#include "scenes/scene.h"

namespace morphoflow {

int runReactionDiffusion(const Scene& scene, const RunOptions& options);

// Shared with the coupled runner: the scene's initial state; its parameter
// maps, perturbations, fixed regions and anisotropy; a divergence check.
template <int D>
void initialState(const Scene& scene, RDSolver<D>* rd);
template <int D>
void applyScene(const Scene& scene, RDSolver<D>* rd);
template <int D>
void checkFinite(const RDSolver<D>& rd, const std::string& where);
// A species as floats, for frames and dumps.
template <int D>
Grid<float, D> toFloat(const Grid<double, D>& src) {
  Grid<float, D> f(src.dims());
  for (size_t i = 0; i < f.size(); ++i) f[i] = float(src[i]);
  return f;
}

}  // namespace morphoflow
