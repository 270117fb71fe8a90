// arview dialogue check <dialogue.yaml>
// arview dialogue chat <dialogue.yaml> [--seed N] [--seconds-per-line S]
// (docs/dialogue.md)

#include <unistd.h>

#include <cstdint>
#include <iostream>
#include <memory>
#include <string>

#include "app/cli/commands.h"
#include "dialogue/chat.h"
#include "dialogue/dialogue.h"
#include "dialogue/dialogue_file.h"

namespace arview::app {

namespace {

struct DialogueArgs {
  std::string file;
  std::uint64_t seed = 0;
  dialogue::ChatOptions chat;
};

void RunCheck(const DialogueArgs& args) {
  int errors = 0;
  for (const dialogue::CheckFinding& finding : dialogue::CheckDialogueFile(args.file)) {
    std::cout << (finding.error ? "error: " : "warning: ") << finding.what << "\n";
    errors += finding.error;
  }
  if (errors > 0) throw CommandError(args.file + ": " + std::to_string(errors) + " error(s): undefined names or unreachable states");
  const dialogue::Dialogue d = dialogue::LoadDialogue(args.file);
  std::size_t states = 0;
  std::size_t transitions = 0;
  for (const dialogue::Machine& m : d.machines) {
    states += m.states.size();
    transitions += m.transitions.size();
  }
  std::cout << args.file << ": " << d.machines.size() << " machines, " << states << " states, " << transitions
            << " transitions, " << d.variables.size() << " variables: ok\n";
}

void RunChatCommand(const DialogueArgs& args) {
  dialogue::DialogueManager manager(dialogue::LoadDialogue(args.file), args.seed);
  dialogue::ChatOptions options = args.chat;
  options.prompt = ::isatty(STDIN_FILENO) == 1;
  dialogue::RunChat(manager, std::cin, std::cout, options);
}

}  // namespace

void AddDialogueCommand(CLI::App& app) {
  auto args = std::make_shared<DialogueArgs>();
  auto* cmd = app.add_subcommand("dialogue", "Dialogue files: check one, or chat with it in the terminal ('dialogue check', 'dialogue chat')");
  cmd->require_subcommand(1);

  auto* check = cmd->add_subcommand(
      "check", "Read a dialogue file and name what is wrong: undefined names, bad patterns, unreachable states (exit 1 on errors)");
  check->add_option("file", args->file, "Dialogue file (YAML, see docs/dialogue.md)")->required();
  check->callback([args] { RunCheck(*args); });

  auto* chat = cmd->add_subcommand(
      "chat", "Converse with a dialogue by typing: each line is what the character hears; /wait S, /viewer ..., /expect, "
              "/emotions, /quit");
  chat->add_option("file", args->file, "Dialogue file (YAML, see docs/dialogue.md)")->required();
  chat->add_option("--seed", args->seed, "Seed of the choice between machines of equal priority")->capture_default_str();
  chat->add_option("--seconds-per-line", args->chat.seconds_per_line,
                   "Dialogue time that passes with each line typed (time conditions, emotion decay)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  chat->callback([args] { RunChatCommand(*args); });
}

}  // namespace arview::app
