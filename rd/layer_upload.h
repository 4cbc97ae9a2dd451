// LayerUpload<D>: everything a device's reaction-diffusion layer
// (gpu/gpu_rd_layer.h) reads of an assembled RDSolver, named, and filled
// once by layerUpload(): the device layer holds this, never the solver.
// Small values are copied; the assembled operators, specs and fields are
// borrowed (const, and the solver that owns them outlives the layer).
#pragma once

#include <vector>

#include "rd/rd_solver.h"

namespace morphoflow {

template <int D>
struct LayerUpload {
  RDSettings settings;
  IVec<D> cells{};
  double h = 1.0;
  int species = 0;
  std::vector<double> diffusion;   // per species
  std::vector<double> parameters;  // the model's uniform values
  std::vector<int> clamped;        // species kept >= 0 (the model's projection)
  std::vector<const std::vector<double>*> parameterMaps;  // per parameter (empty: uniform)
  std::vector<const std::vector<double>*> state;          // the species to start from
  std::vector<const AnisotropicSystem<D>*> operators;     // per species: -h^2 lap or -h^2 div(sigma grad)
  std::vector<const std::vector<uint8_t>*> fixedMasks;    // per species (null: no held cells)
  std::vector<const std::vector<double>*> fixedValues;
  std::vector<const Vector*> dirichletFaces;              // per species, with Dirichlet walls
  const DiffusionTensorSpec<D>* tensor = nullptr;         // a fixed or shaped tensor (seed 004)
  std::vector<bool> anisotropic;                          // the species it applies to
  const CosineLobeSpec* lobes = nullptr;                  // Kim & Lin's cosine lobes
  std::vector<bool> lobed;                                // the species they apply to
};

template <int D>
LayerUpload<D> layerUpload(const RDSolver<D>& rd) {
  LayerUpload<D> u;
  u.settings = rd.settings();
  u.cells = rd.cells();
  u.h = rd.h();
  u.species = rd.species();
  u.diffusion = rd.diffusion();
  for (size_t k = 0; k < rd.model().info().parameters.size(); ++k) {
    u.parameters.push_back(rd.parameter(int(k)));
    u.parameterMaps.push_back(&rd.parameterField(int(k)));
  }
  u.clamped = rd.model().info().clamped;
  u.tensor = rd.diffusionTensorSpec();
  u.lobes = rd.cosineLobes();
  for (int s = 0; s < rd.species(); ++s) {
    const size_t si = size_t(s);
    u.state.push_back(&rd.field(s).values());
    u.operators.push_back(&rd.diffusionOperator(s));
    const bool held = si < rd.fixedMasks().size() && !rd.fixedMasks()[si].empty();
    u.fixedMasks.push_back(held ? &rd.fixedMasks()[si] : nullptr);
    u.fixedValues.push_back(held ? &rd.fixedValues()[si] : nullptr);
    u.dirichletFaces.push_back(rd.settings().boundary == RDBoundary::Dirichlet ? &rd.dirichletFaces(s) : nullptr);
    u.anisotropic.push_back(rd.anisotropic(s));
    u.lobed.push_back(rd.lobed(s));
  }
  return u;
}

}  // namespace morphoflow
