#include "app/commands.h"

namespace arview::app {

void AddReplayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay", "Run the whole pipeline on a recording: track, animate, render, composite");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("replay"); });
}

}  // namespace arview::app
