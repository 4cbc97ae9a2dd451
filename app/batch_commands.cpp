// `morphoflow batch`, `sweep` and `gather`: many runs, each in its own
// process, on one machine or as a farm's shards (batch/).
#include <memory>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "batch/batch.h"

namespace morphoflow {

namespace {

// The options batch and sweep share.
void addBatchOptions(CLI::App* cmd, BatchOptions* b) {
  cmd->add_option("--jobs", b->jobs, "runs at once; the machine's threads are divided between them")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--shard", b->shard, "I/N: only every N-th run, from the I-th (0-based)")
      ->check([](const std::string& s) { return s.empty() ? std::string("expected I/N, got ''") : std::string(); });
  cmd->add_option("--set", b->sets, "override a scene key in every run: key.path=value (TOML value)")
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--resume", b->resume, "skip runs completed with the same settings; resume interrupted ones");
  cmd->add_flag("--quiet", b->quiet, "no progress lines (the summary is still printed)");
  cmd->add_option("--out", b->out, "output folder: one folder per run inside it")->capture_default_str();
}

}  // namespace

void addBatchCommands(CLI::App& app, Commands* commands) {
  auto batch = std::make_shared<BatchOptions>();
  CLI::App* batchCmd =
      app.add_subcommand("batch", "run several scenes, each in its own process, into OUT/<scene name>");
  batchCmd->add_option("scenes", batch->scenes, "scene files")->required();
  batchCmd->add_flag("--keep-going", batch->keepGoing, "run the valid scenes when some are invalid");
  addBatchOptions(batchCmd, batch.get());
  commands->add(batchCmd, [batch] { return runBatch(*batch); });

  auto sweep = std::make_shared<BatchOptions>();
  auto sweepScene = std::make_shared<std::string>();
  CLI::App* sweepCmd =
      app.add_subcommand("sweep", "run a scene over every combination of values, into OUT/<key=value,...>");
  sweepCmd->add_option("scene", *sweepScene, "scene file")->required();
  sweepCmd->add_option("--vary", sweep->varies, "key=start:stop:count or key=[a,b,c] (TOML values)")
      ->required()
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  addBatchOptions(sweepCmd, sweep.get());
  commands->add(sweepCmd, [sweep, sweepScene] {
    sweep->scenes = {*sweepScene};
    return runSweep(*sweep);
  });

  auto gatherDir = std::make_shared<std::string>();
  CLI::App* gatherCmd = app.add_subcommand("gather", "merge the shards' summaries of a batch or sweep folder");
  gatherCmd->add_option("dir", *gatherDir, "the folder the shards wrote into (--out)")->required();
  commands->add(gatherCmd, [gatherDir] { return gatherBatch(*gatherDir); });
}

}  // namespace morphoflow
