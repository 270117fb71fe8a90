#include "app/commands.h"

namespace arview::app {

void AddCalibrateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("calibrate", "Calibrate a camera from chessboard or ChArUco photos");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("calibrate"); });
}

}  // namespace arview::app
