#include "rd/model_registry.h"

#include <sstream>

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

const std::vector<const ReactionModel*>& allModels() {
  static const ModelAdapter<models::Turing> turing;
  static const ModelAdapter<models::TuringSanderson> turingSanderson;
  static const ModelAdapter<models::GrayScott> grayScott;
  static const ModelAdapter<models::GrayScottSanderson> grayScottSanderson;
  static const ModelAdapter<models::FitzHughNagumo> fhn;
  static const ModelAdapter<models::Barkley> barkley;
  static const ModelAdapter<models::BarkleyTurbulent> barkleyTurbulent;
  static const ModelAdapter<models::MeinhardtSpots> meinhardt;
  static const ModelAdapter<models::Brusselator> brusselator;
  static const ModelAdapter<models::GiererMeinhardt> gierer;
  static const ModelAdapter<models::Oregonator> oregonator;
  static const ModelAdapter<models::MeinhardtLateral> lateral;
  static const ModelAdapter<models::CoupledBrusselator> coupled;
  static const ModelAdapter<models::OregonatorThreeLayer> oregonator3;
  static const std::vector<const ReactionModel*> all = {
      &turing, &turingSanderson, &grayScott, &grayScottSanderson, &fhn,     &barkley,  &barkleyTurbulent,
      &meinhardt, &brusselator, &gierer,   &oregonator,  &lateral,     &coupled, &oregonator3};
  return all;
}

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
