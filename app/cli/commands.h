#pragma once
// Each subcommand of `arview` lives in its own file app/cli/cmd_<name>.cpp and registers itself
// here. A callback reports failure by throwing; main() turns the exception into one line on
// stderr and a non-zero exit.

#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

#include "base/error.h"

namespace arview::app {

// Thrown by a command to exit with a specific code after its message.
struct CommandError : Error {
  explicit CommandError(const std::string& message, int exit_code = 1) : Error(message), code(exit_code) {}
  int code;
};

void AddCalibrateCommand(CLI::App& app);
void AddImportCommand(CLI::App& app);
void AddSynthCommand(CLI::App& app);
void AddRecordCommand(CLI::App& app);
void AddCameraCommand(CLI::App& app);
void AddMapCommand(CLI::App& app);
void AddMapExtendCommand(CLI::App& map_command);  // `arview map extend`, under `arview map`
void AddTrackCommand(CLI::App& app);
void AddEvalCommand(CLI::App& app);
void AddAnimCommand(CLI::App& app);
void AddPlaceCommand(CLI::App& app);
void AddRenderCommand(CLI::App& app);
void AddSayCommand(CLI::App& app);
void AddViewCommand(CLI::App& app);
void AddReplayCommand(CLI::App& app);
void AddRunCommand(CLI::App& app);
void AddDemoCommand(CLI::App& app);
void AddInfoCommand(CLI::App& app);
void AddDialogueCommand(CLI::App& app);

}  // namespace arview::app
