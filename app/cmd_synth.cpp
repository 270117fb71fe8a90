#include "app/commands.h"

namespace arview::app {

void AddSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "Render synthetic recordings with exact ground truth ('synth room')");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("synth"); });
}

}  // namespace arview::app
