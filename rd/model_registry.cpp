#include "rd/model_registry.h"

#include <sstream>
#include <tuple>

#include "rd/model_adapter.h"
#include "rd/models.h"

namespace morphoflow {

void NewtonStats::merge(const NewtonStats& o) {
  cells += o.cells;
  failures += o.failures;
  maxIterations = std::max(maxIterations, o.maxIterations);
  maxResidual = std::max(maxResidual, o.maxResidual);
}

bool newtonSolve(const ReactionModel& m, const double* x0, const double* p, double dt, double* x,
                 int* iterations, double* residual) {
  unsigned clamped = 0;
  for (int s : m.info().clamped) clamped |= 1u << s;
  NewtonResult r = implicitReactionCell<ReactionModel::kMaxSpecies>(
      m.species(), x0, dt, x, [&](const double* y, double* out) { m.rates(y, p, out); },
      [&](const double* y, double* J) { m.jacobian(y, p, J); }, clamped);
  if (iterations) *iterations = r.iterations;
  if (residual) *residual = r.residual;
  return r.converged;
}

namespace {

// One adapter of each model of the list (rd/models.h).
template <class... M>
const std::vector<const ReactionModel*>& adapted(std::tuple<M...>*) {
  static const std::tuple<ModelAdapter<M>...> adapters;
  static const std::vector<const ReactionModel*> all =
      std::apply([](const auto&... a) { return std::vector<const ReactionModel*>{&a...}; }, adapters);
  return all;
}

}  // namespace

const std::vector<const ReactionModel*>& allModels() { return adapted(static_cast<models::All*>(nullptr)); }

const ReactionModel* findModel(const std::string& name) {
  for (const ReactionModel* m : allModels())
    if (m->info().name == name) return m;
  return nullptr;
}

std::vector<std::string> modelNames() {
  std::vector<std::string> v;
  for (const ReactionModel* m : allModels()) v.push_back(m->info().name);
  return v;
}

std::string describeModel(const ReactionModel& m) {
  const ModelInfo& in = m.info();
  std::ostringstream o;
  o << in.name << ": " << in.title << "\n";
  std::istringstream eq(in.equations);
  for (std::string line; std::getline(eq, line);) o << "    " << line << "\n";
  o << "  species:";
  for (size_t s = 0; s < in.species.size(); ++s)
    o << " " << in.species[s] << " (initial " << in.initial[s] << ", diffusion " << in.diffusion[s] << ")";
  o << "\n  parameters:";
  for (const ParameterInfo& p : in.parameters) o << "\n    " << p.name << " = " << p.value << "  (" << p.meaning << ")";
  o << "\n";
  return o.str();
}

}  // namespace morphoflow
