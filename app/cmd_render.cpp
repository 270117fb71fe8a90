#include "app/commands.h"

namespace arview::app {

void AddRenderCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render one frame of a scene from a given camera pose");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("render"); });
}

}  // namespace arview::app
