// `morphoflow bench SUITE`: the benchmark suites (bench/), the memory benchmark, the studio's (studio/), the
// lit preview's (preview_bench.h), and
// after `bench coupling --backend gpu`'s cases the GPU's dispatch budget.
#include <memory>

#include <CLI/CLI.hpp>

#include "app/bench_arguments.h"
#include "app/commands.h"
#include "app/dispatch_budget.h"
#include "app/memory_bench.h"
#include "app/preview_bench.h"
#include "studio/studio_bench.h"

namespace morphoflow {

void addBenchCommand(CLI::App& app, Commands* commands) {
  auto a = std::make_shared<BenchArguments>();
  CLI::App* cmd = addBenchSubcommand(app, a.get(), std::string(benchSuiteNames()) + ", memory, studio, preview");
  commands->add(cmd, [a] {
    return runBench(*a, [](const BenchArguments& b) {
      if (b.suite == "studio" && b.bench.backend != "gpu") {
        runStudioBench(MORPHOFLOW_SCENE_DIR, b.bench.minSeconds, b.bench.json);
        return 0;
      }
      if (b.suite == "coupling" && b.bench.backend == "gpu") {
        const int status = runBench(b);  // the library's cases, then the budget
        return status != 0 ? status : reportDispatchBudget(MORPHOFLOW_SCENE_DIR, b.bench.json);
      }
      if (b.suite == "preview" && b.bench.backend != "gpu") return runPreviewBench(b.bench) ? 0 : 1;
      if (b.suite != "memory" || b.bench.backend == "gpu") return -1;
      return runMemoryBench(b.bench) ? 0 : 1;
    });
  });
}

}  // namespace morphoflow
