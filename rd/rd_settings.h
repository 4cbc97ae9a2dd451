// Settings of a reaction-diffusion layer, as resolved from a scene.
#pragma once

#include <string>
#include <vector>

namespace morphoflow {

enum class RDIntegrator {
  ExplicitEuler,  // x += dt (R(x) + d lap x)
  SemiImplicit,   // (1 - dt d lap) x' = x + dt R(x)            (seed 000 eq. 28)
  KimLin,         // x^ = x + dt R(x^) by Newton; (1 - dt d lap) x' = x^   (seed 001 eq. 6, 13)
  CrankNicolson,  // (1 - dt/2 d lap) x' = (1 + dt/2 d lap) x + dt R(x)   (seed 004 sec. 4)
};

// The integrator's weight on the implicit diffusion: every integrator is a
// theta scheme (1 - theta dt d lap) x' = ... (explicit 0, Crank-Nicolson 1/2, else 1).
inline double diffusionTheta(RDIntegrator i) {
  return i == RDIntegrator::ExplicitEuler ? 0.0 : i == RDIntegrator::CrankNicolson ? 0.5 : 1.0;
}

enum class RDBoundary { Periodic, Neumann, Dirichlet };

enum class RDLinearSolver { MGPCG, ICPCG };

struct RDSettings {
  std::string model = "gray-scott";
  std::vector<int> resolution{256, 256};
  std::vector<double> size{256.0, 256.0};     // domain extent; cell size h = size / resolution
  std::vector<double> diffusion;              // per species (empty: the model's defaults)
  std::vector<double> parameters;             // per parameter, uniform values (empty: defaults)
  RDIntegrator integrator = RDIntegrator::KimLin;
  RDBoundary boundary = RDBoundary::Periodic;
  std::vector<double> dirichletValues;        // per species, for RDBoundary::Dirichlet
  bool lookupTable = false;                   // Kim & Lin sec. 3.2 precomputed reaction table
  int lookupSize = 256;                       // table samples per species axis
  RDLinearSolver linearSolver = RDLinearSolver::MGPCG;
  double tolerance = 1e-8;                    // relative residual of the diffusion solves
  std::vector<int> frozen;                    // species held at their initial values
};

}  // namespace morphoflow
