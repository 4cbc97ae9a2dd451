// `morphoflow run SCENE`: one scene, through run/'s driver.
#include <climits>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "core/error.h"
#include "core/number_text.h"
#include "run/run_options.h"

namespace morphoflow {

namespace {

// Parses "A:B" (either side may be empty; each a whole number).
void parseFrames(const std::string& s, RunOptions* o) {
  const size_t colon = s.find(':');
  if (colon == std::string::npos)
    throw UserError({"--frames", 0, 0}, "", "expected A:B (first and last frame, inclusive), got '" + s + "'");
  const std::string a = s.substr(0, colon), b = s.substr(colon + 1);
  const std::optional<long> first = a.empty() ? 0L : parseWhole(a), last = b.empty() ? -1L : parseWhole(b);
  if (!first || !last || *first > INT_MAX || *last > INT_MAX)
    throw UserError({"--frames", 0, 0}, "", "expected whole numbers in A:B, got '" + s + "'", "e.g. --frames 10:20");
  o->firstFrame = int(*first);
  o->lastFrame = int(*last);
  if (o->firstFrame < 0 || (o->lastFrame >= 0 && o->lastFrame < o->firstFrame))
    throw UserError({"--frames", 0, 0}, "", "expected 0 <= A <= B in A:B, got '" + s + "'");
}

struct RunArguments {
  RunOptions run;
  std::string frames;
};

}  // namespace

void addRunCommand(CLI::App& app, Commands* commands) {
  auto a = std::make_shared<RunArguments>();
  RunOptions& run = a->run;
  CLI::App* cmd = app.add_subcommand("run", "run a scene");
  cmd->add_option("scene", run.scene, "scene file (.toml)")->required();
  // Each --set takes one value, so scene files may follow it.
  cmd->add_option("--set", run.overrides, "override a scene key: key.path=value (TOML value)")
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--out", run.out, "output directory")->capture_default_str();
  cmd->add_option("--backend", run.backend, "serial | tbb | gpu")
      ->check(CLI::IsMember({"serial", "tbb", "gpu"}))
      ->capture_default_str();
  cmd->add_option("--threads", run.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  cmd->add_option("--frames", a->frames, "A:B: write frames A to B (inclusive), stop after B");
  cmd->add_flag("--resume", run.resume, "continue from the newest intact checkpoint in --out");
  cmd->add_flag("--force", run.force, "with --resume: continue even though the scene changed");
  cmd->add_flag("--quiet", run.quiet, "no progress output");
  commands->add(cmd, [a] {
    if (a->run.force && !a->run.resume)
      throw UserError({"--force", 0, 0}, "", "--force only applies with --resume", "add --resume, or drop --force");
    if (!a->frames.empty()) parseFrames(a->frames, &a->run);
    return runScene(a->run);
  });
}

}  // namespace morphoflow
