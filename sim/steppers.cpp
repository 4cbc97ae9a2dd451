#include "sim/steppers.h"

#include <fmt/format.h>

#include "core/error.h"
#include "coupling/cpu_coupled_stepper.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_coupled_stepper.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_layer_steppers.h"
#include "gpu/gpu_models.h"
#include "gpu/gpu_newton_check.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

namespace {

// The first stage of the scene with no GPU program, or "".
std::string missingGpuStage(const Scene& s) {
  const RDScene& rd = s.rd;
  if (s.hasFluid && !rd.enabled) return "";
  if (gpuSpecies(rd.settings.model) == 0) return "the reaction of model " + rd.settings.model;
  if (s.hasFluid && gpuSpecies(rd.settings.model) != 2)
    return "the chemicals' advection for a model of " + std::to_string(gpuSpecies(rd.settings.model)) +
           " species (the coupled gpu step carries two)";
  if (rd.settings.lookupTable) return "the reaction lookup table (rd.lookup_table)";
  if (s.velocity.enabled) return "the layer carried by a given [velocity]";
  if (rd.generalized.enabled) return "generalized (non-Gaussian) diffusion ([rd.generalized])";
  return "";
}

void checkGpuRuns(const Scene& scene) {
  const std::string stage = missingGpuStage(scene);
  if (!stage.empty())
    throw UserError({scene.path, 0, 0}, "--backend", "the gpu backend has no program yet for " + stage,
                    "run this scene with --backend tbb; docs/gpu.md lists what the gpu backend runs");
  const GpuInfo g = gpuInfo();
  if (!g.available) throw UserError({"--backend", 0, 0}, "", "no usable GPU context: " + g.reason, "use --backend tbb");
  // Kim & Lin's Newton, checked against the CPU's in the scene's precision (gpu/gpu_newton_check.h).
  const GpuPrecision real = scene.gpuPrecision;
  if (scene.rd.enabled && scene.rd.settings.integrator == RDIntegrator::KimLin)
    if (const std::string defect = gpuNewtonDefect(scene.rd.settings.model, real); !defect.empty())
      throw UserError({scene.path, 0, 0}, "rd.integrator",
                      fmt::format("this GPU ({}, {}) computes Kim & Lin's implicit reaction of model {} wrongly in {} "
                                  "precision: {}",
                                  g.renderer, g.version, scene.rd.settings.model, precisionName(real), defect),
                      real == GpuPrecision::Double
                          ? "run this scene with gpu.precision = \"float\", or with --backend tbb; docs/gpu.md says why"
                          : "run this scene with --backend tbb; docs/gpu.md says why");
  // Checked before anything is allocated: the fluid's buffers, and the
  // layer's (two float buffers per species for the explicit step).
  size_t cells = 1;
  for (int n : scene.rd.settings.resolution) cells *= size_t(n);
  size_t need = 0;
  if (scene.rd.enabled)  // (the layer's, an upper bound of the explicit step's)
    need = scene.dimension == 2 ? GpuRDLayer<2>::deviceBytes(cells, gpuSpecies(scene.rd.settings.model), real)
                                : GpuRDLayer<3>::deviceBytes(cells, gpuSpecies(scene.rd.settings.model), real);
  if (scene.hasFluid) {
    const std::vector<int>& r = scene.fluid.resolution;
    need += scene.dimension == 2 ? GpuFluid<2>::deviceBytes({r[0], r[1]}, real)
                                 : GpuFluid<3>::deviceBytes({r[0], r[1], r[2]}, real);
  }
  const size_t have = GlContext::instance().availableBytes();
  if (have > 0 && need > have)
    throw UserError({scene.path, 0, 0}, scene.hasFluid ? "grid.resolution" : "rd.resolution",
                    fmt::format("the GPU has {:.0f} MiB free and this scene needs {:.0f} MiB", double(have) / (1 << 20),
                                double(need) / (1 << 20)),
                    "use a smaller grid, or --backend tbb");
}

}  // namespace

void checkBackend(const Scene& scene, Backend backend) {
  if (backend == Backend::Gpu) checkGpuRuns(scene);
}

std::vector<RaisedTolerance> raisedTolerances(const Scene& scene, Backend backend) {
  std::vector<RaisedTolerance> raised;
  if (backend != Backend::Gpu) return raised;
  const double floor = toleranceFloor(scene.gpuPrecision);
  auto check = [&](bool used, const char* key, double asked) {
    if (used && asked < floor && scene.givenKeys.count(key)) raised.push_back({key, asked, floor});
  };
  check(scene.hasFluid, "fluid.pressure_tolerance", scene.fluid.pressureTolerance);
  check(scene.rd.enabled && !scene.rd.plainExplicit(), "rd.tolerance", scene.rd.settings.tolerance);
  return raised;
}

template <int D>
std::unique_ptr<FluidStepper<D>> makeFluidStepper(const Scene& scene, Backend backend, FluidSolver<D>* host) {
  if (backend != Backend::Gpu) return std::make_unique<CpuFluidStepper<D>>(host);
  auto gpu = std::make_unique<GpuFluid<D>>(host->settings(), host->constraints(), scene.gpuPrecision);
  gpu->fromHost(*host);
  return gpu;
}

template <int D>
std::unique_ptr<LayerStepper<D>> makeLayerStepper(const Scene& scene, Backend backend, RDSolver<D>* host) {
  // The plain explicit step in single precision; everything else (every
  // integrator, maps, fixed regions, frozen species, Dirichlet walls) in the scene's.
  if (backend == Backend::Gpu) {
    if (scene.rd.plainExplicit() && host->species() == 2) return std::make_unique<GpuExplicitLayerStepper<D>>(*host);
    return std::make_unique<GpuLayerStepper<D>>(*host, scene.gpuPrecision);
  }
  if (scene.rd.plainExplicit())
    if (auto fused = FusedLayerStepper<D>::create(host, scene.rd.generalized.species)) return fused;
  return std::make_unique<CpuLayerStepper<D>>(host);
}

template <int D>
std::unique_ptr<CoupledStepper<D>> makeCoupledStepper(const Scene& scene, Backend backend, FluidSolver<D>* fluid,
                                                  ARDSolver<D>* ard, const ChemicalDomain<D>& domain) {
  const CouplingScene& C = scene.coupling;
  if (backend == Backend::Gpu)
    return std::make_unique<GpuCoupledStepper<D>>(*fluid, ard->rd(), domain, C.interpolation, C.mode, C.rdTimeScale,
                                                  scene.gpuPrecision);
  return std::make_unique<CpuCoupledStepper<D>>(fluid, ard, backend);
}

template <int D>
CoarseAdvance<D> coarseAdvance(const Scene& scene, Backend backend) {
  if (backend != Backend::Gpu) return {};
  return [real = scene.gpuPrecision](RDSolver<D>* level, long steps, double dt) {
    GpuLayerStepper<D> layer(*level, real);
    layer.advance(dt, steps);
    layer.toHost(level);
  };
}

template std::unique_ptr<FluidStepper<2>> makeFluidStepper<2>(const Scene&, Backend, FluidSolver<2>*);
template std::unique_ptr<FluidStepper<3>> makeFluidStepper<3>(const Scene&, Backend, FluidSolver<3>*);
template std::unique_ptr<LayerStepper<2>> makeLayerStepper<2>(const Scene&, Backend, RDSolver<2>*);
template std::unique_ptr<LayerStepper<3>> makeLayerStepper<3>(const Scene&, Backend, RDSolver<3>*);
template std::unique_ptr<CoupledStepper<2>> makeCoupledStepper<2>(const Scene&, Backend, FluidSolver<2>*, ARDSolver<2>*,
                                                              const ChemicalDomain<2>&);
template std::unique_ptr<CoupledStepper<3>> makeCoupledStepper<3>(const Scene&, Backend, FluidSolver<3>*, ARDSolver<3>*,
                                                              const ChemicalDomain<3>&);
template CoarseAdvance<2> coarseAdvance<2>(const Scene&, Backend);
template CoarseAdvance<3> coarseAdvance<3>(const Scene&, Backend);

}  // namespace morphoflow
