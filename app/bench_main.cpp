// morphoflow-bench: the benchmark suites of bench/ in an executable of their
// own. It links neither OpenVDB nor OpenImageIO (the renderers' libraries),
// so a GPU node without Debian's packages runs it from a bundle of a few
// shared libraries (scripts/gpu-bundle). `morphoflow-bench bench SUITE` takes
// the options of `morphoflow bench SUITE`; the memory suite, which runs
// scenes, is the full command line's alone.
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/bench_arguments.h"
#include "core/error.h"

using namespace morphoflow;

int main(int argc, char** argv) {
  CLI::App app{"morphoflow-bench: the benchmark suites of morphoflow"};
  app.require_subcommand(1);
  BenchArguments a;
  addBenchSubcommand(app, &a, benchSuiteNames());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return runBench(a);
  } catch (const UserError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "internal error: " << e.what() << "\n";
    return 1;
  }
}
