// The command groups of the command line: each adds its subcommands and
// their options to the app, with the action that runs when one is given.
// The options live in the actions (shared with the parser's bindings).
#pragma once

#include <functional>
#include <utility>
#include <vector>

namespace CLI {
class App;
}

namespace morphoflow {

struct Commands {
  // The subcommand and what it does; its exit status (0, or 2 for a user error it reports itself).
  std::vector<std::pair<CLI::App*, std::function<int()>>> actions;
  void add(CLI::App* command, std::function<int()> action) { actions.emplace_back(command, std::move(action)); }
};

void addRunCommand(CLI::App& app, Commands* commands);         // run (run_command.cpp)
void addBatchCommands(CLI::App& app, Commands* commands);      // batch, sweep, gather (batch_commands.cpp)
void addInspectCommands(CLI::App& app, Commands* commands);    // validate, info, list (inspect_commands.cpp)
void addBenchCommand(CLI::App& app, Commands* commands);       // bench (bench_command.cpp)
void addTextureCommands(CLI::App& app, Commands* commands);    // analyze, plot, texton (texture_commands.cpp)
void addStudioCommand(CLI::App& app, Commands* commands);      // studio (studio_command.cpp)
void addBlenderCommand(CLI::App& app, Commands* commands);     // blender (blender_command.cpp)

}  // namespace morphoflow
