#include "app/commands.h"

namespace arview::app {

void AddImportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("import", "Import a public dataset (middlebury, strecha, tum, images, video) as a recording");
  cmd->allow_extras();
  cmd->callback([] { NotBuiltYet("import"); });
}

}  // namespace arview::app
