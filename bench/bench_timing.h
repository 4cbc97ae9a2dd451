// Shared pieces of the benchmark suites: the grid cases a suite runs
// (narrowed by --size) and timing a step until enough wall time has passed.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace morphoflow {

struct BenchCase {
  int dim, n;
};

// The suite's cases, or only those of `size` cells per axis (a 2D case of that
// size when the suite has none) when size > 0.
inline std::vector<BenchCase> selectBenchCases(std::vector<BenchCase> all, int size) {
  if (size <= 0) return all;
  std::vector<BenchCase> pick;
  for (BenchCase c : all)
    if (c.n == size) pick.push_back(c);
  if (pick.empty()) pick = {{2, size}};
  return pick;
}

// The seconds one call of fn() takes.
template <typename Fn>
double timeOnce(Fn&& fn) {
  auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Calls step() (after which afterStep() may read the solver's statistics)
// until at least minSeconds have been timed and at least 5 steps, at most 200;
// returns the step times in seconds, in the order run.
template <typename Step, typename After>
std::vector<double> timeSteps(double minSeconds, Step&& step, After&& afterStep) {
  std::vector<double> times;
  double total = 0;
  while ((total < minSeconds || times.size() < 5) && times.size() < 200) {
    const double t = timeOnce(step);
    times.push_back(t);
    total += t;
    afterStep();
  }
  return times;
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace morphoflow
