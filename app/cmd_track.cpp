#include "app/commands.h"

namespace arview::app {

void AddTrackCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("track", "Track a recording against a map and write its trajectory");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("track"); });
}

}  // namespace arview::app
