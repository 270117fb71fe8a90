#include "app/commands.h"

namespace arview::app {

void AddMapCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("map", "Build the map of a scene from a recording with COLMAP ('map info' describes one)");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("map"); });
}

}  // namespace arview::app
