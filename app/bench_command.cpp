// `morphoflow bench SUITE`: the benchmark suites (bench/) and the memory benchmark (run/).
#include <memory>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "bench/bench_command.h"
#include "run/memory_bench.h"

namespace morphoflow {

void addBenchCommand(CLI::App& app, Commands* commands) {
  auto a = std::make_shared<BenchArguments>();
  CLI::App* cmd = addBenchSubcommand(app, a.get(), std::string(benchSuiteNames()) + ", memory");
  commands->add(cmd, [a] {
    return runBench(*a, [](const BenchArguments& b) {
      if (b.suite != "memory" || b.bench.backend == "gpu") return -1;
      return runMemoryBench(b.bench) ? 0 : 1;
    });
  });
}

}  // namespace morphoflow
