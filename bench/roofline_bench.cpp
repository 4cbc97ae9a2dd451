// Suite `roofline`: the machine's memory bandwidth, STREAM's triad
// (a = b + s c over arrays far larger than the caches, 24 bytes an element),
// with 1 and 2 threads; then, against it, the kernels of the rd, coupling
// and fluid suites (their explicit steps, advections, the pressure operator
// and V-cycle, the viscosity's Chebyshev steps, Kim & Lin's step) at their
// 2D 1024^2 and 3D 128^3 sizes: each one's
// compulsory bytes per cell update (what it must read and write at least
// once), its measured rate, and the fraction of the triad's bandwidth that
// rate moves. A fraction near 1 says the kernel runs at memory speed; far
// below, it is bound by arithmetic or latency.
#include <algorithm>
#include <fstream>
#include <functional>
#include <iostream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "bench/bench_setups.h"
#include "bench/bench_suites.h"
#include "bench/bench_timing.h"
#include "bench/step_traffic.h"
#include "core/parallel.h"
#include "core/chebyshev.h"
#include "core/multigrid.h"
#include "coupling/chemical_advection.h"
#include "fluid/advection.h"
#include "fluid/fluid_solver.h"
#include "fluid/viscosity.h"
#include "rd/fused_explicit.h"
#include "rd/generalized_diffusion.h"
#include "rd/model_registry.h"
#include "rd/rd_solver.h"

namespace morphoflow {

double triadBandwidth(int threads, double minSeconds) {
  ThreadLimit limit(threads);
  const size_t n = size_t(1) << 24;  // 3 x 128 MiB
  std::vector<double> a(n), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  auto triad = [&] { parallelFor(n, [&](size_t i) { a[i] = b[i] + s * c[i]; }, size_t(1) << 16); };
  triad();
  const std::vector<double> t = timeSteps(minSeconds, triad, [] {});
  return 24.0 * double(n) / median(t) / 1e9;
}

std::array<double, 3> suiteTriads(double minSeconds) {
  std::array<double, 3> triad{};
  for (int threads : {1, 2}) triad[size_t(threads)] = triadBandwidth(threads, minSeconds);
  std::cout << fmt::format("triad: {:.1f} GB/s with 1 thread, {:.1f} with 2\n", triad[1], triad[2]);
  return triad;
}

namespace {

struct Kernel {
  std::string name;
  int dim, n;
  double bytes;                  // compulsory bytes per cell update
  std::function<void()> step;    // one pass over the grid (or `passes` of them)
  std::shared_ptr<int> passes;   // set by step: its passes over the grid (null: 1)
};

double cellsOf(int dim, int n) { return dim == 2 ? double(n) * n : double(n) * n * n; }

template <int D>
IVec<D> cube(int n) {
  IVec<D> c;
  for (int a = 0; a < D; ++a) c[a] = n;
  return c;
}

// The solvers' kernels on the fluid suite's cavity and the rd suite's layer.
// A solve's rate counts one cell update per cell and iteration (Chebyshev
// step); its compulsory bytes are one pass over its vectors and, where the
// kernel must read them, its coefficients (c, diag and D face weights:
// 4 (D + 2) bytes).
template <int D>
void addSolverKernels(int n, double explicitDt, std::vector<Kernel>* out) {
  const double coefficients = 4.0 * (D + 2);
  auto fluid = std::make_shared<FluidSolver<D>>(benchCavity<D>(n));
  fluid->step(1.0 / n);  // a flow to solve for
  const LaplaceSystem<D>& P = fluid->projection().system();
  auto x = std::make_shared<Vector>(P.size()), y = std::make_shared<Vector>(P.size());
  for (size_t i = 0; i < x->size(); ++i) (*x)[i] = std::sin(0.001 * double(i));
  P.removeNullSpace(x.get());
  // y = A x in double: read x and the coefficients, write y.
  out->push_back({"pressure A x (double)", D, n, 16.0, [fluid, &P, x, y] { P.apply(*x, y.get()); }, nullptr});
  // One V-cycle from zero (MGPCG's preconditioner): read r, write z, the
  // fine coefficients at least once; the cycle's sweeps are on top.
  auto mg = std::make_shared<Multigrid<D>>(P);
  out->push_back({"pressure V-cycle (float levels)", D, n, 16.0 + coefficients,
                  [fluid, mg, x, y] { mg->apply(*x, y.get()); }, nullptr});
  // The viscosity's Chebyshev iteration on the x velocity at the suite's
  // step (dt = h): a step reads two float iterates and g, writes one, for
  // each cell it updates (cyclic: half of them, so 8 bytes a cell).
  auto visc = std::make_shared<ViscousSystem<D>>(viscousSystem<D>(fluid->constraints(), 0));
  const double h = 1.0 / n;
  visc->setRate(fluid->settings().viscosity * h / (h * h));
  auto cheb = std::make_shared<Chebyshev<D>>(visc->A);
  auto b = std::make_shared<Vector>(visc->A.size()), u = std::make_shared<Vector>(visc->A.size());
  for (size_t i = 0; i < b->size(); ++i) (*b)[i] = visc->A.c[i] > 0 ? std::sin(0.002 * double(i)) : 0.0;
  auto steps = std::make_shared<int>(0);
  out->push_back({"viscosity Chebyshev step (float)", D, n, 16.0 * cheb->cellsPerStep() / double(visc->A.size()),
                  [visc, cheb, b, u, steps] {
                    std::fill(u->begin(), u->end(), 0.0);
                    *steps = cheb->solve(*b, u.get(), SolverOptions{1e-6, 1000}).iterations;
                  },
                  steps});
  // Kim & Lin's step at ten times the explicit limit (Newton per cell, one
  // implicit diffusion solve per species): two double species read and written.
  auto kl = std::make_shared<RDSolver<D>>(benchGrayScott<D>(n, 1.0, RDIntegrator::KimLin), *findModel("gray-scott"));
  pearsonStart(kl.get());
  out->push_back({"rd Kim & Lin step", D, n, 32, [kl, explicitDt] { kl->step(10.0 * explicitDt); }, nullptr});
}

// The kernels, each with the state it steps (kept alive by the closures).
template <int D>
void addKernels(int n, std::vector<Kernel>* out) {
  // rd: RDSolver's double explicit step (two species read and written: 32 B).
  auto rd =
      std::make_shared<RDSolver<D>>(benchGrayScott<D>(n, 1.0, RDIntegrator::ExplicitEuler), *findModel("gray-scott"));
  pearsonStart(rd.get());
  const double dt = 0.9 * rd->explicitDiffusionLimit();
  out->push_back({"rd explicit (double)", D, n, 32, [rd, dt] { rd->step(dt); }, nullptr});
  // rd: the fused float step (two float species read and written: 16 B), and with the 5 x 5 kernel in 2D.
  auto fused = std::shared_ptr<FusedExplicitRD<D>>(
      FusedExplicitRD<D>::create("gray-scott", cube<D>(n), 1.0, true, {0.2, 0.1}, {}).release());
  for (int s = 0; s < 2; ++s)
    for (size_t i = 0; i < fused->field(s).size(); ++i) fused->field(s)[i] = float(rd->field(s)[i]);
  out->push_back({"rd fused (float)", D, n, 16, [fused, dt] { fused->step(dt); }, nullptr});
  if constexpr (D == 2) {
    auto k5 = std::shared_ptr<FusedExplicitRD<D>>(
        FusedExplicitRD<D>::create("gray-scott", cube<D>(n), 1.0, true, {0.2, 0.1}, {}).release());
    k5->setKernel(GeneralizedDiffusion(*kramersMoyalPreset("d"), n, n, 2.2).kernel(), {});
    for (int s = 0; s < 2; ++s) k5->field(s) = fused->field(s);
    out->push_back({"rd fused 5x5 (float)", D, n, 16, [k5, dt] { k5->step(dt); }, nullptr});
  }
  // coupling: two double species traced back through a float MAC velocity on the same grid (read 2 x 8 + D x 4, write 2
  // x 8).
  std::array<bool, D> walls{};
  auto vel = std::make_shared<MacVelocity<D>>(cube<D>(n), 1.0 / n, walls);
  for (int a = 0; a < D; ++a)
    for (size_t i = 0; i < (*vel)[a].size(); ++i) (*vel)[a][i] = float(0.3 * std::sin(0.001 * double(i) + a));
  ChemicalDomain<D> dom;
  dom.cells = cube<D>(n);
  dom.h = 1.0 / n;
  dom.periodic = walls;
  auto adv = std::make_shared<ChemicalAdvector<D>>(dom, ChemicalInterpolation::Linear);
  auto chem = std::make_shared<std::array<Grid<double, D>, 2>>();
  for (Grid<double, D>& g : *chem) g = Grid<double, D>(cube<D>(n), 0.5);
  out->push_back({"coupling chemical advection", D, n, 32.0 + 4.0 * D, [adv, vel, chem] {
                    adv->advect(*vel, 0.5 / 1024, {&(*chem)[0], &(*chem)[1]});
                  }, nullptr});
  // fluid: semi-Lagrangian advection of the velocity through itself (read and write D floats).
  auto dst = std::make_shared<MacVelocity<D>>(cube<D>(n), 1.0 / n, walls);
  out->push_back({"fluid velocity advection", D, n, 8.0 * D, [vel, dst] {
                    advectVelocity(*vel, 0.5 / 1024, AdvectionScheme::SemiLagrangian, dst.get());
                  }, nullptr});
  addSolverKernels<D>(n, dt, out);
}

}  // namespace

bool runRooflineBench(const BenchOptions& o) {
  nlohmann::json all = {{"triad", nlohmann::json::object()}, {"kernels", nlohmann::json::array()}};
  double bw[3] = {0, 0, 0};
  for (int threads : {1, 2}) {
    bw[threads] = triadBandwidth(threads, o.minSeconds);
    all["triad"][std::to_string(threads)] = bw[threads];
    std::cout << fmt::format("triad, {} thread{}: {:.1f} GB/s\n", threads, threads > 1 ? "s" : "", bw[threads])
              << std::flush;
  }
  std::cout << fmt::format("{:<30} {:>4} {:>6} {:>7} {:>10} {:>16} {:>10} {:>9}\n", "kernel", "dim", "n", "threads",
                           "B/update", "Mcell-updates/s", "GB/s", "of triad");
  std::vector<Kernel> kernels;
  for (BenchCase c : selectBenchCases({{2, 1024}, {3, 128}}, o.size)) {
    kernels.clear();
    if (c.dim == 2) addKernels<2>(c.n, &kernels);
    else addKernels<3>(c.n, &kernels);
    for (const Kernel& k : kernels)
      for (int threads : {1, 2}) {
        ThreadLimit limit(threads);
        k.step();
        const double passes = k.passes ? double(std::max(1, *k.passes)) : 1.0;
        const double rate = passes * cellsOf(k.dim, k.n) / median(timeSteps(o.minSeconds, k.step, [] {}));
        const double gbs = rate * k.bytes / 1e9;
        std::cout << fmt::format("{:<30} {:>4} {:>6} {:>7} {:>10.0f} {:>16.1f} {:>10.1f} {:>9.2f}\n", k.name, k.dim,
                                 k.n, threads, k.bytes, rate / 1e6, gbs, gbs / bw[threads])
                  << std::flush;
        all["kernels"].push_back({{"kernel", k.name}, {"dim", k.dim}, {"n", k.n}, {"threads", threads},
                                  {"bytes_per_cell_update", k.bytes}, {"cell_updates_per_second", rate},
                                  {"gb_per_second", gbs}, {"fraction_of_triad", gbs / bw[threads]}});
      }
  }
  if (!o.json.empty()) writeFileAtomically(o.json, all.dump(2) + "\n");
  return true;
}

}  // namespace morphoflow
