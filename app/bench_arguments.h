// The `bench` subcommand's options and their checks, shared by the
// morphoflow command line (which adds the memory and studio suites) and the
// morphoflow-bench executable (the suites of bench/ alone).
#pragma once

#include <functional>
#include <string>

#include "bench/bench_suites.h"

namespace CLI {
class App;
}

namespace morphoflow {

struct BenchArguments {
  std::string suite;
  BenchOptions bench;
  bool interpolationGiven = false;
  bool warmUpGiven = false;
  std::string suites;  // the suite names, for errors
};

// Adds `bench SUITE [options]` to app; `suites` names the suites for --help.
CLI::App* addBenchSubcommand(CLI::App& app, BenchArguments* a, const std::string& suites);

// Checks the options (UserError, exit 2), then runs the suite: `other`'s
// (its exit status, or -1 when the suite is not its own), else this library's.
int runBench(const BenchArguments& a, const std::function<int(const BenchArguments&)>& other = {});

}  // namespace morphoflow
