// `morphoflow studio [SCENE]`: the scene running in the browser (docs/studio.md).
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <iostream>
#include <memory>
#include <thread>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "core/error.h"
#include "run/child_process.h"
#include "run/stop_signal.h"
#include "scenes/scene_loader.h"
#include "studio/studio_server.h"

namespace morphoflow {

namespace {

struct StudioArguments {
  std::string scene;
  ServerOptions server;
  StudioOptions studio;
};

int serve(const StudioArguments& a) {
  StopSignals signals;
  StudioOptions studio = a.studio;
  studio.executable = selfExecutable();
  const std::string text = a.scene.empty() ? std::string() : readSceneText(a.scene);
  StudioServer server(a.server, studio, text, a.scene, MORPHOFLOW_SCENE_DIR);
  std::cout << "morphoflow studio: open " << server.url() << "\n"
            << "  (the token in the address is the key: keep it to yourself; Ctrl-C stops the studio)" << std::endl;
  while (!StopSignals::received()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::cout << "morphoflow studio: stopped" << std::endl;
  return 0;
}

}  // namespace

void addStudioCommand(CLI::App& app, Commands* commands) {
  auto a = std::make_shared<StudioArguments>();
  CLI::App* cmd = app.add_subcommand("studio", "see, steer and paint a running scene in the browser");
  cmd->add_option("scene", a->scene, "scene file (.toml); none: the page offers the shipped scenes");
  cmd->add_option("--port", a->server.port, "port (0: any free one)")->capture_default_str();
  cmd->add_option("--listen", a->server.listen, "address to bind (0.0.0.0: every network; the token still guards it)")
      ->capture_default_str();
  cmd->add_option("--backend", a->studio.backend, "serial | tbb | gpu")
      ->check(CLI::IsMember({"serial", "tbb", "gpu"}))
      ->capture_default_str();
  cmd->add_option("--threads", a->studio.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  cmd->add_option("--out", a->studio.out, "where Render writes the saved scene and its run")->capture_default_str();
  commands->add(cmd, [a] { return serve(*a); });
}

}  // namespace morphoflow
