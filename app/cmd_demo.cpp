#include "app/commands.h"

namespace arview::app {

void AddDemoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run everything on the embedded default scene (no camera, no downloads)");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("demo"); });
}

}  // namespace arview::app
