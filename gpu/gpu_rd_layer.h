// A reaction-diffusion layer (rd/rd_solver.h) on the GPU, in float or double
// (gpu.precision; docs/gpu.md "Precision"): the species in storage buffers, the reaction of any model
// (Kim & Lin's per-cell Newton, or the rates for the explicit and
// semi-implicit integrators; shaders/rd_react.comp), then every integrator's
// theta scheme on the isotropic diffusion, (I - theta dt d lap) x' = x + ...,
// solved by CG (diagonal preconditioner while the identity dominates, one
// multigrid V-cycle beyond, as on the CPU) to rd.tolerance, warm-started from
// the last step's diffusive change. Parameter maps, fixed regions, frozen
// species, periodic, zero-flux and Dirichlet walls, a fixed diffusion tensor
// (seed 004 eq. 11-17), Kim & Lin's cosine lobes rebuilt from the state
// every step (shaders/rd_lobes.comp; their systems preconditioned by the
// diagonal); sim/steppers.cpp refuses the rest.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/backend.h"
#include "core/state_archive.h"
#include "gpu/gpu_buffer.h"
#include "gpu/kernel_modes.h"
#include "rd/layer_upload.h"
#include "rd/rd_solver.h"

namespace morphoflow {

class GpuLaplace;
class GpuMultigrid;
class GpuPcg;
struct GpuPcgWork;

template <int D>
class GpuRDLayer {
 public:
  // From the layer's description (rd/layer_upload.h: the settings, model,
  // parameters, operators and initial species of an assembled RDSolver).
  explicit GpuRDLayer(const LayerUpload<D>& upload, GpuPrecision real = GpuPrecision::Double);
  ~GpuRDLayer();
  GpuRDLayer(const GpuRDLayer&) = delete;
  GpuRDLayer& operator=(const GpuRDLayer&) = delete;

  void step(double dt);
  // The step's statistics (Newton failures and iterations, the worst diffusion solve). The diffusion solves decide
  // their convergence on the device (gpu_gate.h) and everything is read back at steps 1, 2, 4, 8 and then every 16th
  // (statsDue): a step reports the last read's diffusion results, and Newton's failures and most iterations since the
  // read before on the steps that read them (0 on the others, so their sums and maxima over the steps are exact).
  const RDStepStats& lastStats() const { return stats_; }
  int species() const { return species_; }
  size_t cells() const { return n_; }
  GpuBuffer& field(int s) { return x_[size_t(s)]; }
  void upload(int s, const std::vector<double>& values);
  std::vector<double> download(int s) const;
  // The warm starts of the diffusion solves (checkpoints).
  void save(StateWriter* out) const;
  void load(const StateReader& in);
  // Device bytes a layer of n cells and that many species allocates (its solvers included).
  static size_t deviceBytes(size_t n, int species, GpuPrecision real);
  size_t deviceBytes() const { return deviceBytes(n_, species_, real_); }
  GpuPrecision precision() const { return real_; }
  double tolerance() const { return up_.settings.tolerance; }  // its diffusion solves' (raised to the floor)

 private:
  struct Diffusion;
  struct Stages;  // the step's stages (rd/rd_step.h)
  void react(double dt, bool implicit);
  SolverResult diffuse(int s, double thetaDt);
  void vectorOp(VectorOp op, const GpuBuffer& x, GpuBuffer* y, double a, double b,
                const GpuBuffer* held = nullptr) const;
  void holdFixed();
  // x += dt R + explicitD (-A x + ghost faces) (rd_solver.cpp's explicit part, its order)
  void thetaStep(const GpuBuffer& rates, GpuBuffer* x, const GpuBuffer& ax, const GpuBuffer& faces, double dt,
                 double explicitD, double ghost) const;
  // Each lobed species' operator from its state at the step's start (eq. 14-17).
  void buildLobes();
  // A shaped tensor's operator from the shape species at the step's start (seed 004 eq. 18-19).
  void buildTensor();
  void tensorKernel(TensorMode mode, GpuLaplace* target);
  bool rebuilt(int s) const;  // whether species s's operator is rebuilt every step
  // rd_lobes.comp on `species` into `target` (and the Dirichlet faces' weights).
  void lobeKernel(LobeMode mode, int species, GpuLaplace* target, GpuBuffer* faces);

  static constexpr int kMax = ReactionModel::kMaxSpecies;
  LayerUpload<D> up_;
  GpuPrecision real_;
  int species_ = 2;
  size_t n_ = 0;
  std::array<double, 12> params_{};
  unsigned clamped_ = 0;
  std::array<GpuBuffer, kMax> x_, rates_;
  GpuBuffer work_;  // the species' solves' (one after another), swapped with the species solved
  std::shared_ptr<GpuPcgWork> pcgWork_;
  GpuBuffer stats_buffer_;
  GpuBuffer maps_;                    // the parameter maps, one after another
  std::array<int, 12> mapAt_{};       // where parameter k's map starts (-1: uniform)
  std::array<GpuBuffer, kMax> fixedMask_, fixedValue_;  // per species (empty: free)
  std::array<GpuBuffer, kMax> faces_;    // Dirichlet faces per cell (empty: none)
  std::array<GpuBuffer, kMax> frozen_;   // frozen species' values, taken at the first step
  std::array<bool, kMax> isFrozen_{}, isFixed_{};
  bool frozenTaken_ = false;
  GpuBuffer allHeld_;                 // a mask of ones (frozen species)
  GpuBuffer lobeA_, rot_;             // a(theta) per cell; cos, sin of theta0 per cell
  GpuBuffer direction_, lambda1_, lambda2_, sigma_;  // a shaped tensor's spec and components
  // -lap or -div(sigma grad) (scale 1/h^2): the explicit part, and the operators rebuilt each step (else none)
  std::array<std::unique_ptr<GpuLaplace>, kMax> operator_;
  std::array<std::unique_ptr<Diffusion>, kMax> diffusion_;
  RDStepStats stats_;
  long steps_ = 0;
  void readStats();
};

}  // namespace morphoflow
