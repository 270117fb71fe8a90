// arview: one binary, one subcommand per job (see docs/architecture.md, "The command line").

#include <cstdio>
#include <exception>
#include <iostream>

#include "app/cli/commands.h"
#include "app/cli/numeric_flags.h"
#include "base/cancellation.h"
#include "base/heap_reuse.h"
#include "figure/humanoid.h"

namespace {

// CLI11 messages may span lines; the contract is one clear line on stderr.
// A message may quote text from a file (a name, a token): line breaks become spaces, so that it
// stays one line, and other control characters are shown as \xNN (an escape sequence in a
// hostile file must not drive the terminal). Bytes from 0x80 up pass: UTF-8 file names.
std::string OneLine(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n' || c == '\r') {
      out += ' ';
    } else if ((byte < 0x20 && c != '\t') || byte == 0x7f) {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace arview::app;
  arview::KeepFreedHeapForReuse();  // SIFT's scale space reused from frame to frame (base/heap_reuse.h)
  arview::figure::RegisterBuiltinCharacters();  // "builtin:figure" wherever an asset is named
  CLI::App app{"arview: marker-less augmented reality with view-adaptive characters", "arview"};
  app.require_subcommand(1);
  app.fallthrough(false);
  app.get_formatter()->column_width(34);
  app.set_version_flag("--version", "arview 0.1.0");

  AddCalibrateCommand(app);
  AddImportCommand(app);
  AddSynthCommand(app);
  AddRecordCommand(app);
  AddCameraCommand(app);
  AddMapCommand(app);
  AddTrackCommand(app);
  AddEvalCommand(app);
  AddAnimCommand(app);
  AddPlaceCommand(app);
  AddRenderCommand(app);
  AddSayCommand(app);
  AddViewCommand(app);
  AddReplayCommand(app);
  AddRunCommand(app);
  AddDemoCommand(app);
  AddInfoCommand(app);
  AddDialogueCommand(app);
  GuardNumericOptions(app);  // NaN, infinities and negative unsigned values are refused

  // CLI11 would report an unknown command as a missing subcommand; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      known = known || sub->get_name() == argv[1];
    }
    if (!known) {
      std::cerr << "arview: unknown command '" << argv[1] << "' (see 'arview --help' for the list)\n";
      return 2;
    }
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "arview: " << OneLine(e.what()) << " (see 'arview --help')\n";
    return e.get_exit_code() != 0 ? e.get_exit_code() : 2;
  } catch (const arview::CancelledError& e) {
    // Ctrl-C or SIGTERM: one line saying what stopped and what was kept; 130 / 143 as a shell.
    std::cerr << "arview: " << OneLine(e.what()) << "\n";
    return e.exit_code();
  } catch (const CommandError& e) {
    std::cerr << "arview: " << OneLine(e.what()) << "\n";
    return e.code;
  } catch (const arview::Error& e) {  // every module's errors: a bad file, device or value
    std::cerr << "arview: " << OneLine(e.what()) << "\n";
    return 1;
  } catch (const std::exception& e) {  // not ours (out of memory, a library's own exception)
    std::cerr << "arview: " << OneLine(e.what()) << "\n";
    return 1;
  }
  return 0;
}
