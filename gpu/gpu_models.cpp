#include "gpu/gpu_models.h"

#include <fmt/format.h>

#include "gpu/shader_source.h"
#include "rd/model_registry.h"

namespace morphoflow {

namespace {

// The GLSL side of the kernels' dialect (kernels/README.md): T the
// precision, LIT(v) a literal in it (v is not exact in float), every result
// `precise` (no fused multiply-adds: each operation rounds as the CPU's does).
std::string dialect(int species, bool doublePrecision) {
  return fmt::format("#define NSPECIES {}\n#define NPARAMETERS {}\n", species, ReactionModel::kMaxParameters) +
         (doublePrecision ? "#define T double\n#define LIT(v) v##lf\n" : "#define T float\n#define LIT(v) v\n") +
         "#define PT T\n#define TV(v) T(v)\n#define KERNEL void\n#define OUT(type, name) precise out type name\n"
         "#define PRECISE precise\n";
}

std::string functions(const std::string& rates, const std::string& jacobian) {
  return "#define RATES void " + rates + "(T x[NSPECIES], PT p[NPARAMETERS], precise out T r[NSPECIES])\n" +
         "#define JACOBIAN void " + jacobian +
         "(T x[NSPECIES], PT p[NPARAMETERS], precise out T J[NSPECIES * NSPECIES])\n";
}

}  // namespace

int gpuSpecies(const std::string& name) {
  const ReactionModel* m = findModel(name);
  return m ? m->species() : 0;
}

std::string gpuReaction(const std::string& name, GpuPrecision precision) {
  const ReactionModel* m = findModel(name);
  if (!m) return "";
  const bool doublePrecision = precision == GpuPrecision::Double;
  const ModelKernel& k = m->kernel();
  std::string text = dialect(m->species(), doublePrecision) + k.defines;
  if (!k.base.empty())  // the kernels of the model it builds on; that model's own rates under other names
    text += functions("baseRates", "baseJacobian") + shaderSource(k.base) + "#undef RATES\n#undef JACOBIAN\n";
  return text + functions("modelRates", "modelJacobian") + shaderSource(k.file);
}

}  // namespace morphoflow
