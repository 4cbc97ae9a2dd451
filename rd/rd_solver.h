// RDSolver<D>: a reaction-diffusion layer on a cell-centred grid, advanced by
// one of the integrators of rd_settings.h. Diffusion is the standard 5-/7-point
// Laplacian (seed 001 eq. 4) with periodic, zero-flux (Neumann) or fixed-value
// (Dirichlet, through a ghost cell mirrored about the wall) boundaries; its
// implicit solves use the shared LaplaceSystem / PCG / multigrid of core/.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/anisotropic_system.h"
#include "core/chebyshev.h"
#include "core/grid.h"
#include "core/multigrid.h"
#include "core/pcg.h"
#include "core/solver_result.h"
#include "core/state_archive.h"
#include "core/work_pool.h"
#include "rd/cosine_lobe.h"
#include "rd/diffusion_tensor.h"
#include "rd/generalized_diffusion.h"
#include "rd/rd_settings.h"
#include "rd/reaction_lut.h"
#include "rd/reaction_model.h"

namespace morphoflow {

// The diffusion solves' multigrid cycle, on both backends: three smoothing
// sweeps each way, as the fluid's viscosity. The identity term makes these
// systems better conditioned than a Poisson problem, and a third sweep costs
// less than the outer iteration it saves (Gray-Scott ARD at 256^2 and 512^2:
// 4 -> 3 iterations to 1e-8, RD stage 15.5 -> 14.6 ms at 512^2; docs/performance.md).
inline constexpr MultigridOptions kDiffusionCycle{3, 3, 4};

struct RDStepStats {
  NewtonStats newton;       // implicit reaction (Kim & Lin)
  SolverResult diffusion;   // worst species solve
  int lookups = 0;          // cells served by the lookup table
};

template <int D>
class RDSolver {
 public:
  RDSolver(const RDSettings& settings, const ReactionModel& model);
  ~RDSolver();

  const ReactionModel& model() const { return model_; }
  const RDSettings& settings() const { return settings_; }
  const IVec<D>& cells() const { return cells_; }
  double h() const { return h_; }
  int species() const { return int(x_.size()); }
  Grid<double, D>& field(int s) { return x_[size_t(s)]; }
  const Grid<double, D>& field(int s) const { return x_[size_t(s)]; }
  const std::vector<double>& diffusion() const { return d_; }

  // Parameter k as a per-cell field (replaces its uniform value).
  void setParameterField(int k, std::vector<double> values);
  const std::vector<double>& parameterField(int k) const { return fields_[size_t(k)]; }
  double parameter(int k) const { return params_.constant[size_t(k)]; }
  // Cells whose species values are held fixed (seed 004 fig. 20's fixed rows):
  // after every step, cell i of species s is reset to values[s][i] wherever
  // masks[s][i]; an empty masks[s] leaves species s free.
  void setFixedCells(std::vector<std::vector<uint8_t>> masks, std::vector<std::vector<double>> values);
  const std::vector<std::vector<uint8_t>>& fixedMasks() const { return fixedMasks_; }
  const std::vector<std::vector<double>>& fixedValues() const { return fixedValues_; }
  // Inhomogeneous anisotropic diffusion (seed 004 eq. 11-19): the spec's
  // species diffuse by div(d sigma grad); a shaped (dynamic) spec rebuilds
  // sigma from the current state at every step.
  void setDiffusionTensor(DiffusionTensorSpec<D> spec);
  bool anisotropic(int s) const { return !tensorSpecies_.empty() && tensorSpecies_[size_t(s)]; }
  const DiffusionTensorSpec<D>* diffusionTensorSpec() const { return tensorSpec_.get(); }
  // Kim & Lin's cosine-lobe anisotropy (seed 001 eq. 14-17): the spec's
  // species diffuse by div(d a(theta) grad), a(theta) rebuilt from each
  // species' own gradient at every step. Not combined with a tensor.
  void setCosineLobes(CosineLobeSpec spec);
  const CosineLobeSpec* cosineLobes() const { return lobeSpec_.get(); }
  bool lobed(int s) const { return !lobeSpecies_.empty() && lobeSpecies_[size_t(s)]; }
  // McGraw's generalized (non-Gaussian) diffusion (seed 000 eq. 19-37): the
  // species (empty: all) diffuse by d A, A the 5 x 5 Kramers-Moyal operator,
  // in place of the Laplacian. 2D and periodic only (throws otherwise).
  void setGeneralizedDiffusion(std::shared_ptr<const GeneralizedDiffusion> op, std::vector<int> species);
  const GeneralizedDiffusion* generalizedDiffusion() const { return general_.get(); }
  bool generalized(int s) const { return !generalSpecies_.empty() && generalSpecies_[size_t(s)]; }
  // The operator -h^2 div(sigma grad) (or -h^2 lap) that species s diffuses by.
  const AnisotropicSystem<D>& diffusionOperator(int s) const {
    return lobed(s) ? lobeSystem_[size_t(s)] : anisotropic(s) ? tensor_ : laplacian();
  }

  // Per cell, the weight of its Dirichlet faces in species s's operator (the
  // ghost value 2 g enters the right-hand side through it; 0 without Dirichlet walls).
  const Vector& dirichletFaces(int s) const { return boundaryWeights(s); }

  void step(double dt);
  // Lend the diffusion solves' work vectors from `pool` for each step (and
  // give them back after), to share them with the stages around it; null:
  // keep them.
  void setWorkPool(WorkPool* pool) { pool_ = pool; }
  const RDStepStats& lastStats() const { return stats_; }
  // Everything step() reads besides the settings and the scene's maps (the
  // species, time, held values, the diffusion solves' warm starts), so that
  // load(save()) continues bit for bit.
  void save(StateWriter* out) const;
  void load(const StateReader& in);
  double time() const { return time_; }
  long steps() const { return steps_; }

  // Largest stable explicit-Euler step for the diffusion alone:
  // 2 h^2 / max_s (d_s * Gershgorin bound of its operator); h^2 / (2 D d_max)
  // when isotropic.
  double explicitDiffusionLimit() const;

 private:
  struct Stages;     // the step's stages (rd/rd_step.h)
  struct Diffusion;  // per-species implicit system and its solver state
  // The isotropic -h^2 lap, or with a shift s the implicit system I + s lap
  // as AnisotropicSystem::shifted(s) makes it, built directly.
  LaplaceSystem<D> isotropicSystem(std::optional<double> shift) const;
  const AnisotropicSystem<D>& laplacian() const;
  void react(double dt, bool implicit);
  void applyLaplacian(int s, const Vector& x, Vector* out) const;  // out = lap x (with boundary terms)
  // Returns the solve's result (converged, no iterations when d or theta dt is 0).
  SolverResult solveDiffusion(int s, double theta_dt, Vector* rhs_to_x);
  void holdFixed();
  void buildTensor();
  void buildLobes();
  // -h^2 div(sigma grad) from sigma's components and its Dirichlet ghost weights.
  void assemble(const std::array<std::vector<double>, AnisotropicSystem<D>::kComponents>& sigma,
                AnisotropicSystem<D>* system, Vector* boundary) const;
  const Vector& boundaryWeights(int s) const {
    return lobed(s) ? lobeBoundary_[size_t(s)] : anisotropic(s) ? tensorBoundary_ : boundaryFaces_;
  }

  RDSettings settings_;
  const ReactionModel& model_;
  IVec<D> cells_;
  double h_;
  std::vector<Grid<double, D>> x_;
  std::vector<double> d_;
  ParameterValues params_;
  std::vector<std::vector<double>> fields_;
  size_t cellCount_ = 0;
  // -h^2 lap, with c = 2 per Dirichlet face: built on first use (laplacian()).
  mutable std::unique_ptr<AnisotropicSystem<D>> laplacian_;
  double lapBound_ = 0.0;             // its maxRowAbsSum()
  Vector boundaryFaces_;              // Dirichlet faces per cell (empty unless Dirichlet)
  std::unique_ptr<DiffusionTensorSpec<D>> tensorSpec_;
  std::vector<uint8_t> tensorSpecies_;
  AnisotropicSystem<D> tensor_;       // -h^2 div(sigma grad), c = 2 sigma_aa per Dirichlet face
  Vector tensorBoundary_;             // sum of sigma_aa over the Dirichlet faces per cell
  std::unique_ptr<CosineLobeSpec> lobeSpec_;
  std::vector<uint8_t> lobeSpecies_;
  std::vector<AnisotropicSystem<D>> lobeSystem_;  // per species (used where lobed)
  std::vector<Vector> lobeBoundary_;
  std::shared_ptr<const GeneralizedDiffusion> general_;
  std::vector<uint8_t> generalSpecies_;
  long operatorVersion_ = 0;          // bumped whenever a tensor or lobe operator is rebuilt
  std::vector<std::unique_ptr<Diffusion>> diffusion_;
  Vector scratch_;              // an explicit part's Laplacian (the species take turns)
  std::vector<Vector> rates_;   // per species: R(x) of an explicit reaction
  // The diffusion solves' work vectors, shared: the species take turns.
  Vector solveX_;
  ChebyshevWork chebyshevWork_;
  PcgWorkspace pcgWork_;
  WorkPool* pool_ = nullptr;
  std::vector<std::vector<uint8_t>> fixedMasks_;
  std::vector<std::vector<double>> fixedValues_;
  std::vector<std::vector<double>> frozenValues_;
  ReactionLUT lut_;
  RDStepStats stats_;
  double time_ = 0.0;
  long steps_ = 0;
};

}  // namespace morphoflow
