#include "app/commands.h"

namespace arview::app {

void AddEvalCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "Compare a trajectory with ground truth (ATE, RPE, alignment, plot)");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("eval"); });
}

}  // namespace arview::app
