// `morphoflow validate`, `info` and `list`: scenes checked, the machine's
// backends, the models, scenes and palettes; no simulation.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "app/commands.h"
#include "core/number_text.h"
#include "core/parallel.h"
#include "core/simd_dispatch.h"
#include "gpu/gl_context.h"
#include "rd/model_registry.h"
#include "render/colormap.h"
#include "run/memory_estimate.h"
#include "run/version.h"
#include "scenes/scene_loader.h"
#include "sim/scene_inputs.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

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

int validate(const std::vector<std::string>& scenes) {
  for (const std::string& s : scenes) {
    Scene sc = loadScene(s);
    checkSceneInputs(sc);
    const std::string memory = "needs about " + humanBytes(estimateRunBytes(sc)) + " of memory";
    if (sc.hasFluid)
      std::cout << fmt::format("{}: ok ({}D, {} steps, Re = {:.4g}, {})\n", s, sc.dimension, sc.totalSteps(),
                               sc.reynolds, memory);
    else
      std::cout << fmt::format("{}: ok ({}D, {} steps, reaction-diffusion {}, {})\n", s, sc.dimension, sc.totalSteps(),
                               sc.rd.settings.model, memory);
  }
  return 0;
}

int info() {
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

int list(const std::string& what) {
  if (what == "palettes") {
    for (const auto& n : colormapNames())
      std::cout << n
                << (n == kTwoSpeciesPalette ? "  (two species: the first in red, the second in green; seed 002)" : "")
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

}  // namespace

void addInspectCommands(CLI::App& app, Commands* commands) {
  auto scenes = std::make_shared<std::vector<std::string>>();
  CLI::App* validateCmd = app.add_subcommand("validate", "parse and check scenes; no simulation");
  validateCmd->add_option("scenes", *scenes, "scene files")->required();
  commands->add(validateCmd, [scenes] { return validate(*scenes); });

  CLI::App* infoCmd =
      app.add_subcommand("info", "the backends built, the GL renderer, the CPU's vector features and threads");
  commands->add(infoCmd, info);

  auto what = std::make_shared<std::string>();
  CLI::App* listCmd = app.add_subcommand("list", "list models, scenes or palettes");
  listCmd->add_option("what", *what, "models | scenes | palettes")
      ->required()
      ->check(CLI::IsMember({"models", "scenes", "palettes"}));
  commands->add(listCmd, [what] { return list(*what); });
}

}  // namespace morphoflow
