#include "app/commands.h"

namespace arview::app {

void AddPlaceCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("place", "Place a character on the dominant plane of a map and write a scene file");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("place"); });
}

}  // namespace arview::app
