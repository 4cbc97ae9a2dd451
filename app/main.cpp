// The morphoflow command line: the commands and their options over the
// libraries of run/, batch/ and bench/ (docs/architecture.md).
// Exit status: 0 success, 2 user error (file:line:col on stderr), 1 internal error.
#include <malloc.h>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "batch/batch.h"
#include "gpu/gl_context.h"
#include "run/memory_estimate.h"
#include "run/run_options.h"
#include "app/texture_commands.h"
#include "run/version.h"
#include "run/memory_bench.h"
#include "bench/bench_suites.h"
#include "core/error.h"
#include "core/number_text.h"
#include "core/parallel.h"
#include "core/simd_dispatch.h"
#include "core/simulation.h"
#include "render/colormap.h"
#include "rd/model_registry.h"
#include "scenes/scene_loader.h"

using namespace morphoflow;
namespace fs = std::filesystem;

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

std::vector<fs::path> shippedScenes() {
  std::vector<fs::path> found;
  for (fs::path dir : {fs::path("scenes"), fs::path(MORPHOFLOW_SCENE_DIR)}) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) continue;
    for (auto& e : fs::recursive_directory_iterator(dir, ec))
      if (e.path().extension() == ".toml") found.push_back(e.path());
    if (!found.empty()) break;
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

int main(int argc, char** argv) {
  // Grids and work vectors come from mmap and go back to the system when
  // freed: glibc would otherwise raise its threshold after the first free of
  // such a block and serve later ones from a heap that fragments, so the
  // resident memory of a long run would creep above what it holds.
  mallopt(M_MMAP_THRESHOLD, 256 * 1024);
  CLI::App app{"morphoflow: stable fluids carrying reaction-diffusion patterns"};
  app.require_subcommand(1);
  app.set_version_flag("--version", kVersion);

  RunOptions run;
  std::string frames;
  CLI::App* runCmd = app.add_subcommand("run", "run a scene");
  runCmd->add_option("scene", run.scene, "scene file (.toml)")->required();
  // Each --set takes one value, so scene files may follow it.
  runCmd->add_option("--set", run.overrides, "override a scene key: key.path=value (TOML value)")
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  runCmd->add_option("--out", run.out, "output directory")->capture_default_str();
  runCmd->add_option("--backend", run.backend, "serial | tbb | gpu")
      ->check(CLI::IsMember({"serial", "tbb", "gpu"}))
      ->capture_default_str();
  runCmd->add_option("--threads", run.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  runCmd->add_option("--frames", frames, "A:B: write frames A to B (inclusive), stop after B");
  runCmd->add_flag("--resume", run.resume, "continue from the newest intact checkpoint in --out");
  runCmd->add_flag("--force", run.force, "with --resume: continue even though the scene changed");
  runCmd->add_flag("--quiet", run.quiet, "no progress output");

  BatchOptions batch, sweep;
  auto batchOptions = [](CLI::App* cmd, BatchOptions* b) {
    cmd->add_option("--jobs", b->jobs, "runs at once; the machine's threads are divided between them")
        ->check(CLI::Range(1, 256));
    cmd->add_option("--shard", b->shard, "I/N: only every N-th run, from the I-th (0-based)");
    cmd->add_option("--set", b->sets, "override a scene key in every run: key.path=value (TOML value)")
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    cmd->add_flag("--resume", b->resume, "skip runs completed with the same settings; resume interrupted ones");
    cmd->add_flag("--quiet", b->quiet, "no progress lines (the summary is still printed)");
    cmd->add_option("--out", b->out, "output folder: one folder per run inside it")->capture_default_str();
  };
  CLI::App* batchCmd = app.add_subcommand("batch", "run several scenes, each in its own process, into OUT/<scene name>");
  batchCmd->add_option("scenes", batch.scenes, "scene files")->required();
  batchCmd->add_flag("--keep-going", batch.keepGoing, "run the valid scenes when some are invalid");
  batchOptions(batchCmd, &batch);
  std::string sweepScene;
  CLI::App* sweepCmd = app.add_subcommand("sweep", "run a scene over every combination of values, into OUT/<key=value,...>");
  sweepCmd->add_option("scene", sweepScene, "scene file")->required();
  sweepCmd->add_option("--vary", sweep.varies, "key=start:stop:count or key=[a,b,c] (TOML values)")
      ->required()
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  batchOptions(sweepCmd, &sweep);
  std::string gatherDir;
  CLI::App* gatherCmd = app.add_subcommand("gather", "merge the shards' summaries of a batch or sweep folder");
  gatherCmd->add_option("dir", gatherDir, "the folder the shards wrote into (--out)")->required();

  std::vector<std::string> validateScenes;
  CLI::App* validateCmd = app.add_subcommand("validate", "parse and check scenes; no simulation");
  validateCmd->add_option("scenes", validateScenes, "scene files")->required();

  CLI::App* infoCmd = app.add_subcommand("info", "the backends built, the GL renderer, the CPU's vector features and threads");

  std::string what;
  CLI::App* listCmd = app.add_subcommand("list", "list models, scenes or palettes");
  listCmd->add_option("what", what, "models | scenes | palettes")
      ->required()
      ->check(CLI::IsMember({"models", "scenes", "palettes"}));

  std::string suite;
  BenchOptions bench;
  CLI::App* benchCmd = app.add_subcommand("bench", "run a benchmark suite");
  benchCmd->add_option("suite", suite, std::string("suite: ") + benchSuiteNames())->required();
  benchCmd->add_option("--size", bench.size, "only grids of this many cells per axis")->check(CLI::Range(8, 16384));
  benchCmd->add_option("--json", bench.json, "also write results as JSON");
  benchCmd->add_option("--seconds", bench.minSeconds, "minimum timed seconds per case");
  benchCmd->add_option("--backend", bench.backend, "cpu | gpu")
      ->check(CLI::IsMember({"cpu", "gpu"}))
      ->capture_default_str();
  benchCmd->add_option("--trace", bench.trace, "coupling: write a Chrome trace-event JSON of the stages per thread");

  AnalyzeOptions analyze;
  CLI::App* analyzeCmd = app.add_subcommand("analyze", "variogram and regularity REG of an image or field dump (seed 003)");
  analyzeCmd->add_option("file", analyze.file, "PNG/EXR image or DIR/fields/NNNNNN.exr")->required();
  analyzeCmd->add_option("--channel", analyze.channel, "channel (species) to analyse; default the first");
  analyzeCmd->add_option("--max-lag", analyze.maxLag, "largest spacing in cells (default: a quarter of the smaller side)")
      ->check(CLI::Range(1, 1 << 20));
  analyzeCmd->add_flag("--periodic", analyze.periodic, "pairs wrap around (for tiles of periodic runs)");
  analyzeCmd->add_option("--slice", analyze.slice, "z slice of a 3D dump (default: the middle)")->check(CLI::Range(0, 1 << 20));
  analyzeCmd->add_option("--csv", analyze.csv, "also write the variogram per lag and direction");

  PlotOptions plot;
  CLI::App* plotCmd = app.add_subcommand("plot", "plots: `plot propagator SCENE --out FILE.png` (seed 000 fig. 1)");
  plotCmd->add_option("what", plot.what, "propagator")->required();
  plotCmd->add_option("scene", plot.scene, "a scene with [rd.generalized]")->required();
  plotCmd->add_option("--out", plot.out, "the image (.png)")->required();
  plotCmd->add_option("--set", plot.overrides, "key.path=value overrides, as for run");
  plotCmd->add_option("--tau", plot.tau, "the propagator's time")->capture_default_str();
  plotCmd->add_option("--radius", plot.radius, "|r| of the circle plotted")->capture_default_str();
  plotCmd->add_option("--size", plot.size, "pixels")->capture_default_str()->check(CLI::Range(64, 8192));
  TextonOptions texton;
  CLI::App* textonCmd = app.add_subcommand("texton", "random-walk texton texture (seed 003 eq. 6)");
  textonCmd->add_option("--out", texton.out, "output image (.png or .exr)")->required();
  textonCmd->add_option("--size", texton.walk.width, "field width and height in cells")->capture_default_str()->check(CLI::Range(1, 16384));
  textonCmd->add_option("--elements", texton.walk.elements, "number of textons")->capture_default_str()->check(CLI::Range(1, 10000000));
  textonCmd->add_option("--steps", texton.walk.steps, "random-walk steps")->capture_default_str()->check(CLI::Range(0, 100000000));
  textonCmd->add_option("--step-size", texton.walk.stepSize, "cells per move")->capture_default_str()->check(CLI::Range(1, 16384));
  textonCmd->add_option("--lifetime", texton.walk.lifetime, "mean lifetime L in steps (0: never expire)")->capture_default_str();
  textonCmd->add_option("-p", texton.walk.p, "probability of moving right, given not expired")->capture_default_str();
  textonCmd->add_option("-q", texton.walk.q, "probability of moving left, given not expired")->capture_default_str();
  textonCmd->add_option("--start", texton.start, "pulse | regular | uniform")
      ->check(CLI::IsMember({"pulse", "regular", "uniform"}))->capture_default_str();
  textonCmd->add_option("--radius", texton.walk.radius, "texton disc radius in cells")->capture_default_str();
  textonCmd->add_option("--seed", texton.walk.seed, "random seed")->capture_default_str();
  textonCmd->add_flag("--analyze", texton.analyze, "also print the texture's REG");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  try {
    if (*runCmd) {
      if (run.force && !run.resume)
        throw UserError({"--force", 0, 0}, "", "--force only applies with --resume", "add --resume, or drop --force");
      if (!frames.empty()) parseFrames(frames, &run);
      return runScene(run);
    }
    if (*batchCmd) return runBatch(batch);
    if (*sweepCmd) {
      sweep.scenes = {sweepScene};
      return runSweep(sweep);
    }
    if (*gatherCmd) return gatherBatch(gatherDir);
    if (*validateCmd) {
      for (const std::string& s : validateScenes) {
        Scene sc = loadScene(s);
        const std::string memory = "needs about " + humanBytes(estimateRunBytes(sc)) + " of memory";
        if (sc.hasFluid)
          std::cout << fmt::format("{}: ok ({}D, {} steps, Re = {:.4g}, {})\n", s, sc.dimension, sc.totalSteps(),
                                   sc.reynolds, memory);
        else
          std::cout << fmt::format("{}: ok ({}D, {} steps, reaction-diffusion {}, {})\n", s, sc.dimension,
                                   sc.totalSteps(), sc.rd.settings.model, memory);
      }
      return 0;
    }
    if (*infoCmd) {
      const GpuInfo g = gpuInfo();
      std::cout << fmt::format("morphoflow {}\nbackends: serial, tbb, gpu\n", kVersion);
      if (g.available)
        std::cout << fmt::format("gpu: {} ({}), OpenGL {}\n", g.renderer, g.platform, g.version);
      else
        std::cout << "gpu: unavailable: " << g.reason << "\n";
      std::cout << fmt::format("cpu: {} threads; vector kernels {} (AVX2 {}, AVX-512 {}){}\n", hardwareThreads(),
                               useAvx512() ? "8-lane AVX2, 16-lane AVX-512" : useAvx2() ? "8-lane AVX2" : "4-lane SSE",
                               cpuHasAvx2() ? "present" : "absent", cpuHasAvx512() ? "present" : "absent",
                               std::getenv("MORPHOFLOW_SIMD") ? " (MORPHOFLOW_SIMD set)" : "");
      return 0;
    }
    if (*listCmd) {
      if (what == "palettes") {
        for (const auto& n : colormapNames())
          std::cout << n << (n == kTwoSpeciesPalette ? "  (two species: the first in red, the second in green; seed 002)" : "")
                    << "\n";
        std::cout << "custom: output.gradient = [\"#rrggbb\", ...] (two or more stops, evenly spaced)\n";
      } else if (what == "scenes") {
        for (const auto& p : shippedScenes()) {
          Scene sc = loadScene(p.string());
          if (sc.hasFluid)
            std::cout << fmt::format("{:<48} {}D  Re = {:<8.4g} grid {}\n", p.string(), sc.dimension, sc.reynolds,
                                     fmt::join(sc.fluid.resolution, "x"));
          else
            std::cout << fmt::format("{:<48} {}D  rd {:<19} grid {}\n", p.string(), sc.dimension, sc.rd.settings.model,
                                     fmt::join(sc.rd.settings.resolution, "x"));
        }
      } else {
        for (const ReactionModel* m : allModels()) std::cout << describeModel(*m) << "\n";
      }
      return 0;
    }
    if (*analyzeCmd) return analyzeCommand(analyze);
    if (*plotCmd) return plotCommand(plot);
    if (*textonCmd) {
      texton.walk.height = texton.walk.width;
      return textonCommand(texton);
    }
    if (*benchCmd) {
      if (!bench.trace.empty() && suite != "coupling")
        throw UserError({"--trace", 0, 0}, "", "only the coupling suite writes a trace", "drop --trace or run `bench coupling`");
      // A --size case of n^2 cells (the suites' own sizes are known to fit) needs at most ~1 kB a cell.
      if (const uintmax_t need = uintmax_t(bench.size) * uintmax_t(bench.size) * 1000; need > availableBytes())
        throw UserError({"--size", 0, 0}, "", fmt::format("a {0} x {0} case needs about {1}; this machine has {2} free", bench.size,
                                                          humanBytes(need), humanBytes(availableBytes())),
                        "give a smaller --size");
      if (suite == "memory" && bench.backend != "gpu") return runMemoryBench(bench) ? 0 : 1;
      if (!runBenchSuite(suite, bench))
        throw UserError({"bench", 0, 0}, "", "unknown suite '" + suite + "'", std::string("suites: ") + benchSuiteNames() + ", memory");
      return 0;
    }
  } catch (const UserError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const NonFiniteError& e) {  // before the run loop (a coarse-to-fine start)
    std::cerr << "error: " << e.what() << " (" << e.hint() << ")\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "internal error: " << e.what() << "\n";
    return 1;
  }
  return 1;
}
