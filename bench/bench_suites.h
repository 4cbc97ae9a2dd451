// `morphoflow bench SUITE`: benchmark suites that print a table (and JSON).
#pragma once

#include <string>

namespace morphoflow {

struct BenchOptions {
  int size = 0;            // 0 = the suite's full list of sizes
  std::string json;        // write results here when not empty
  double minSeconds = 1.0; // time each case for at least this long (after warm-up)
  int warmUpSteps = 3;     // fluid: steps before the timed ones (the flow starts to develop)
  std::string trace;       // coupling: write a Chrome trace of the stages here
  std::string backend = "cpu";  // cpu | gpu
  std::string precision = "float";       // gpu: the solver vectors' and layer's, float | double (gpu.precision)
  std::string interpolation = "linear";  // coupling: the chemicals' back-trace sample (coupling_choices.h)
};

// Runs the named suite (on the CPU, or with backend "gpu" the same problems
// on the GPU); returns false when the suite does not exist.
bool runBenchSuite(const std::string& suite, const BenchOptions& options);
const char* benchSuiteNames();

}  // namespace morphoflow
