#include "app/dispatch_budget.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "run/run_options.h"

namespace morphoflow {

int reportDispatchBudget(const std::string& sceneDir, const std::string& json) {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / fmt::format("morphoflow_dispatch_budget_{}", getpid());
  RunOptions opt;
  opt.scene = sceneDir + "/coupled/cavity_gray_scott.toml";
  opt.overrides = {"time.steps=20", "output.every=1000", "output.video=false"};
  opt.out = out.string();
  opt.backend = "gpu";
  opt.quiet = true;
  const int status = runScene(opt);
  if (status != 0) return status;
  const nlohmann::json gpu = nlohmann::json::parse(std::ifstream(out / "run.json"))["gpu"];
  std::error_code ec;
  fs::remove_all(out, ec);
  const double dispatches = gpu["dispatches_per_step"], waits = gpu["host_waits_per_step"];
  const bool within = dispatches <= kDispatchBudget && waits <= kHostWaitBudget;
  std::cout << fmt::format(
      "dispatch budget (the shipped coupled cavity, 20 steps): {:.1f} dispatches a step (budget {:g}), {:.2f} host "
      "waits (budget {:g}): {}\n",
      dispatches, kDispatchBudget, waits, kHostWaitBudget, within ? "within" : "OVER BUDGET");
  if (!json.empty()) {
    nlohmann::json all = nlohmann::json::parse(std::ifstream(json));
    all.push_back({{"case", "dispatch budget"}, {"scene", "coupled/cavity_gray_scott.toml"}, {"steps", 20},
                   {"dispatches_per_step", dispatches}, {"host_waits_per_step", waits},
                   {"dispatch_budget", kDispatchBudget}, {"host_wait_budget", kHostWaitBudget},
                   {"within_budget", within}, {"stages", gpu["stages"]}});
    writeFileAtomically(json, all.dump(2) + "\n");
  }
  return 0;
}

}  // namespace morphoflow
