// ReactionModel: the local kinetics R(x; p) of a reaction-diffusion system
//   dx_s/dt = R_s(x; p) + d_s lap(x_s)
// for n species x and parameters p (each constant or a per-cell field).
//
// A model is written once as a small struct (see models.h) with static
// `rates` and `jacobian`; ModelAdapter<M> turns it into this interface, with
// the per-cell loops (explicit rates, implicit Newton update) inlined.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace morphoflow {

struct ParameterInfo {
  std::string name;
  double value;         // default
  std::string meaning;
};

struct ModelInfo {
  std::string name;                    // scene key, e.g. "gray-scott"
  std::string title;                   // human name and source
  std::string equations;               // plain-text rates, one species per line
  std::vector<std::string> species;    // field names, e.g. {"u", "v"}
  std::vector<ParameterInfo> parameters;
  std::vector<double> diffusion;       // default d_s (domain units^2 / time)
  std::vector<double> initial;         // default uniform state
  double lutLow = 0.0, lutHigh = 1.0;  // lookup-table range of every species
  std::vector<int> clamped;            // species the step clamps at 0
};

// Where a model's rates and Jacobian are written (kernels/models/): the
// file, the model file whose kernels it builds on ("" if none) and the GLSL
// #defines it needs; what the GPU backend embeds (gpu/gpu_models.h).
struct ModelKernel {
  std::string file, base, defines;
};

// Per-cell parameter values: parameter k is constant[k] unless field[k] is set.
struct ParameterValues {
  std::vector<double> constant;
  std::vector<const double*> field;
  void gather(size_t cell, double* p) const {
    for (size_t k = 0; k < constant.size(); ++k) p[k] = field[k] ? field[k][cell] : constant[k];
  }
  bool uniform() const {
    for (const double* f : field)
      if (f) return false;
    return true;
  }
};

// Outcome of implicit reaction updates over a set of cells.
struct NewtonStats {
  long cells = 0;
  long failures = 0;          // cells whose Newton iteration did not converge
  int maxIterations = 0;
  double maxResidual = 0.0;   // max |x - x0 - dt R(x)| (inf-norm) after the update
  void merge(const NewtonStats& o);
};

class ReactionModel {
 public:
  static constexpr int kMaxSpecies = 6;
  static constexpr int kMaxParameters = 12;

  virtual ~ReactionModel() = default;
  virtual const ModelInfo& info() const = 0;
  virtual const ModelKernel& kernel() const = 0;
  int species() const { return int(info().species.size()); }

  // R(x; p) and its Jacobian J[s * n + t] = dR_s / dx_t for one cell.
  virtual void rates(const double* x, const double* p, double* r) const = 0;
  virtual void jacobian(const double* x, const double* p, double* J) const = 0;
  // Applies the model's admissibility rule (e.g. Turing's b >= 0) to one cell.
  void project(double* x) const {
    for (int s : info().clamped)
      if (x[s] < 0) x[s] = 0;
  }

  // out[s][i] = R_s(x[.][i]) for i in [begin, end).
  virtual void evaluate(const double* const* x, const ParameterValues& p, double* const* out, size_t begin,
                        size_t end) const = 0;
  // Implicit Euler on the reaction alone (Kim & Lin eq. 6): every cell's x is
  // replaced by the root of  x - x0 - dt R(x) = 0  (Newton-Raphson with a
  // backtracking line search, started from x0), then projected.
  virtual NewtonStats implicitUpdate(double* const* x, const ParameterValues& p, double dt, size_t begin,
                                     size_t end) const = 0;
};

// Solves one cell's implicit reaction step from x0; returns whether the
// residual met the tolerance and reports iterations and final residual.
bool newtonSolve(const ReactionModel& m, const double* x0, const double* p, double dt, double* x,
                 int* iterations, double* residual);

}  // namespace morphoflow
