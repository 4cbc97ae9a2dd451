#include "app/bench_arguments.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "app/option_checks.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/system_memory.h"

namespace morphoflow {

CLI::App* addBenchSubcommand(CLI::App& app, BenchArguments* a, const std::string& suites) {
  BenchOptions& bench = a->bench;
  a->suites = suites;
  CLI::App* cmd = app.add_subcommand("bench", "run a benchmark suite");
  cmd->add_option("suite", a->suite, "suite: " + suites)->required();
  cmd->add_option("--size", bench.size, "only grids of this many cells per axis")->check(CLI::Range(8, 16384));
  cmd->add_option("--json", bench.json, "also write results as JSON");
  cmd->add_option("--seconds", bench.minSeconds, "minimum timed seconds per case")->check(finiteIn(0.0, 3600.0));
  cmd->add_option("--warm-up", bench.warmUpSteps, "fluid: steps run before the timed ones")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str()
      ->each([a](const std::string&) { a->warmUpGiven = true; });
  cmd->add_option("--backend", bench.backend, "cpu | gpu")->check(CLI::IsMember({"cpu", "gpu"}))->capture_default_str();
  cmd->add_option("--precision", bench.precision, "gpu: float | double (a scene's gpu.precision)")
      ->check(CLI::IsMember({"float", "double"}))
      ->capture_default_str();
  cmd->add_option("--interpolation", bench.interpolation,
                  "coupling: the chemicals' sample, linear | cubic | bspline | bfecc")
      ->check(CLI::IsMember({"linear", "cubic", "bspline", "bfecc"}))
      ->capture_default_str()
      ->each([a](const std::string&) { a->interpolationGiven = true; });
  cmd->add_option("--trace", bench.trace, "coupling: write a Chrome trace-event JSON of the stages per thread");
  return cmd;
}

int runBench(const BenchArguments& a, const std::function<int(const BenchArguments&)>& other) {
  const BenchOptions& bench = a.bench;
  if (a.interpolationGiven && a.suite != "coupling")
    throw UserError({"--interpolation", 0, 0}, "", "only the coupling suite carries chemicals",
                    "drop --interpolation or run `bench coupling`");
  if (a.warmUpGiven && a.suite != "fluid")
    throw UserError({"--warm-up", 0, 0}, "", "only the fluid suite takes warm-up steps",
                    "drop --warm-up or run `bench fluid`");
  if (!bench.trace.empty() && a.suite != "coupling")
    throw UserError({"--trace", 0, 0}, "", "only the coupling suite writes a trace",
                    "drop --trace or run `bench coupling`");
  // A --size case of n^2 cells (the suites' own sizes are known to fit) needs at most ~1 kB a cell.
  if (const uintmax_t need = uintmax_t(bench.size) * uintmax_t(bench.size) * 1000; need > availableBytes())
    throw UserError({"--size", 0, 0}, "",
                    fmt::format("a {0} x {0} case needs about {1}; this machine has {2} free", bench.size,
                                humanBytes(need), humanBytes(availableBytes())),
                    "give a smaller --size");
  // the files it will write, checked before the long work
  if (!bench.json.empty()) checkOutputFile(bench.json, "--json");
  if (!bench.trace.empty()) checkOutputFile(bench.trace, "--trace");
  if (other)
    if (const int status = other(a); status >= 0) return status;
  if (!runBenchSuite(a.suite, bench))
    throw UserError({"bench", 0, 0}, "", "unknown suite '" + a.suite + "'", "suites: " + a.suites);
  return 0;
}

}  // namespace morphoflow
