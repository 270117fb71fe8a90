#include "app/commands.h"

namespace arview::app {

void AddAnimCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("anim", "Inspect characters and view-adaptive blend weights ('anim info', 'anim weights')");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("anim"); });
}

}  // namespace arview::app
