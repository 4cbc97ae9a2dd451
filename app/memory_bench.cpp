#include "app/memory_bench.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "run/child_process.h"
#include "core/error.h"

namespace morphoflow {

namespace {

namespace fs = std::filesystem;

struct MemoryCase {
  std::string what, scene;
  std::vector<std::string> sets;
  double cells;  // the grid's cells (the finer of the fluid's and the layer's for coupled runs)
};

// run.json of `morphoflow run scene sets` (four steps, no outputs) into dir:
// from the third step on a run holds all it keeps between steps (the
// warm-start histories fill in the first two).
nlohmann::json runOnce(const MemoryCase& c, const fs::path& dir) {
  std::vector<std::string> args = {"run", c.scene, "--quiet", "--out", dir.string(), "--set", "output.images=false",
                                   "--set", "output.every=1000"};
  // Four steps (scenes clocked by a duration: four steps' worth of it).
  if (std::none_of(c.sets.begin(), c.sets.end(), [](const std::string& s) { return s.rfind("time.duration", 0) == 0; }))
    args.push_back("--set"), args.push_back("time.steps=4");
  for (const std::string& s : c.sets) args.push_back("--set"), args.push_back(s);
  ChildProcess p(selfExecutable(), args, dir.string() + ".log");
  std::optional<ChildExit> e;
  while (!(e = p.poll())) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (e->code != 0 || e->signal != 0)
    throw std::runtime_error("bench memory: the run of " + c.scene + " failed; see " + dir.string() + ".log");
  return nlohmann::json::parse(std::ifstream(dir / "run.json"));
}

std::string sceneDir() {
  for (fs::path d : {fs::path("scenes"), fs::path(MORPHOFLOW_SCENE_DIR)})
    if (fs::exists(d / "lid_driven_cavity.toml")) return fs::absolute(d).string();
  throw UserError({"scenes", 0, 0}, "", "bench memory runs the shipped scenes and cannot find them",
                  "run it from the project folder");
}

}  // namespace

bool runMemoryBench(const BenchOptions& o) {
  const std::string s = sceneDir();
  const fs::path tmp = fs::temp_directory_path() / fmt::format("morphoflow_bench_memory_{}", getpid());
  fs::create_directories(tmp);
  const int n2 = o.size > 0 ? o.size : 1024, n3 = o.size > 0 ? o.size : 128;
  auto grid = [](int n, int d) { return d == 2 ? fmt::format("[{0},{0}]", n) : fmt::format("[{0},{0},{0}]", n); };
  const std::vector<MemoryCase> cases = {
      {"fluid 2D",
       s + "/lid_driven_cavity.toml",
       {"grid.resolution=" + grid(n2, 2), "time.cfl=0", "time.duration=0.04"},
       double(n2) * n2},
      {"fluid 3D",
       s + "/lid_driven_cavity_3d.toml",
       {"grid.resolution=" + grid(n3, 3), "time.cfl=0", "time.duration=0.08"},
       double(n3) * n3 * n3},
      {"rd 2D kim-lin", s + "/rd/gray_scott_pearson.toml", {"grid.resolution=" + grid(n2, 2)}, double(n2) * n2},
      {"rd 2D explicit (fused)",
       s + "/rd/gray_scott_pearson.toml",
       {"grid.resolution=" + grid(n2, 2), "rd.integrator=\"explicit\"", "time.dt=0.5"},
       double(n2) * n2},
      {"rd 3D kim-lin",
       s + "/rd/turing_lawlor.toml",
       {"grid.resolution=" + grid(n3, 3), "domain.size=" + grid(n3, 3)},
       double(n3) * n3 * n3},
      {"coupled 2D",
       s + "/coupled/cavity_gray_scott.toml",
       {"grid.resolution=" + grid(n2, 2), "rd.resolution=" + grid(n2, 2), "output.video=false"},
       double(n2) * n2},
      {"coupled 3D",
       s + "/coupled/cavity_gray_scott_3d.toml",
       {"grid.resolution=" + grid(n3, 3), "rd.resolution=" + grid(n3, 3), "output.video=false", "output.vdb=false"},
       double(n3) * n3 * n3},
  };
  // The fixed overhead: the smallest coupled 3D run.
  const MemoryCase tiny{"overhead",
                        s + "/coupled/cavity_gray_scott_3d.toml",
                        {"grid.resolution=[8,8,8]", "rd.resolution=[8,8,8]", "output.video=false", "output.vdb=false"},
                        512};
  const double overhead = runOnce(tiny, tmp / "tiny")["peak_memory_bytes"].get<double>();
  std::cout << fmt::format("fixed overhead (a 8^3 coupled run's peak): {:.0f} MiB\n", overhead / (1 << 20));
  std::cout << fmt::format("{:<24} {:>14} {:>12} {:>14} {:>14} {:>10}\n", "case", "cells", "peak MiB",
                           "B/cell (beyond)", "estimate MiB", "est/peak");
  nlohmann::json all = {{"overhead_bytes", overhead}, {"cases", nlohmann::json::array()}};
  int k = 0;
  for (const MemoryCase& c : cases) {
    const nlohmann::json j = runOnce(c, tmp / std::to_string(k++));
    const double peak = j["peak_memory_bytes"].get<double>(), estimate = j["memory_estimate_bytes"].get<double>();
    const double perCell = (peak - overhead) / c.cells;
    std::cout << fmt::format("{:<24} {:>14.0f} {:>12.0f} {:>14.0f} {:>14.0f} {:>10.2f}\n", c.what, c.cells,
                             peak / (1 << 20), perCell, estimate / (1 << 20), estimate / peak)
              << std::flush;
    all["cases"].push_back({{"case", c.what}, {"cells", c.cells}, {"peak_bytes", peak}, {"bytes_per_cell", perCell},
                            {"estimate_bytes", estimate}});
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  if (!o.json.empty()) std::ofstream(o.json) << all.dump(2) << "\n";
  return true;
}

}  // namespace morphoflow
