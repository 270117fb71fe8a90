#include "app/commands.h"

namespace arview::app {

void AddRecordCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("record", "Record a V4L2 camera into a recording folder");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("record"); });
}

}  // namespace arview::app
