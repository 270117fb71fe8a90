#include "app/commands.h"

namespace arview::app {

void AddRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "Run the whole pipeline live on a V4L2 camera or HMD");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("run"); });
}

}  // namespace arview::app
