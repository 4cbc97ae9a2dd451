// The morphoflow command line: the command groups (app/commands.h) over the
// libraries of run/, batch/ and bench/ (docs/architecture.md).
// Exit status: 0 success, 2 user error (file:line:col on stderr), 1 internal error.
#include <malloc.h>

#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "core/error.h"
#include "run/version.h"

using namespace morphoflow;

int main(int argc, char** argv) {
  // Grids and work vectors come from mmap and go back to the system when
  // freed: glibc would otherwise raise its threshold after the first free of
  // such a block and serve later ones from a heap that fragments, so the
  // resident memory of a long run would creep above what it holds.
  mallopt(M_MMAP_THRESHOLD, 256 * 1024);
  CLI::App app{"morphoflow: stable fluids carrying reaction-diffusion patterns"};
  app.require_subcommand(1);
  app.set_version_flag("--version", kVersion);
  Commands commands;
  addRunCommand(app, &commands);
  addBatchCommands(app, &commands);
  addInspectCommands(app, &commands);
  addBenchCommand(app, &commands);
  addStudioCommand(app, &commands);
  addBlenderCommand(app, &commands);
  addTextureCommands(app, &commands);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  try {
    for (const auto& [command, action] : commands.actions)
      if (*command) return action();
  } catch (const UserError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const NonFiniteError& e) {  // before the run loop (a coarse-to-fine start)
    std::cerr << "error: " << e.what() << " (" << e.hint() << ")\n";
    return 2;
  } catch (const std::bad_alloc&) {  // the estimate checked before the run fell short (docs/performance.md, Memory)
    std::cerr
        << "error: out of memory: the machine, its cgroup or this process's limits (ulimit -v, -d) held less than "
           "the run needed (`morphoflow validate SCENE` prints the estimate; give a smaller grid)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "internal error: " << e.what() << "\n";
    return 1;
  }
  return 1;
}
