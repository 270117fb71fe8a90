#include "app/cli/dialogue_flags.h"

namespace arview::app {

void AddDialogueFlags(CLI::App* cmd, DialogueFlags& flags, DialogueInput input) {
  cmd->add_option("--dialogue", flags.dialogue,
                  "A dialogue file (docs/dialogue.md): the character answers what it hears and what the viewer does; "
                  "the HUD shows what was heard, the machine and the emotion, --stats records each turn")
      ->check(CLI::ExistingFile);
  if (input == DialogueInput::kMicrophone) {
    cmd->add_option("--mic", flags.mic,
                    "With --dialogue: listen on this ALSA capture device ('default', 'hw:1', a name from ~/.asoundrc); "
                    "without it the character answers only what the viewer does");
  } else {
    cmd->add_option("--audio-in", flags.audio_in,
                    "With --dialogue: a WAV file the character hears as the replay's clock reaches each sample "
                    "(16-bit PCM; another rate or stereo is converted to 16 kHz mono)")
        ->check(CLI::ExistingFile);
  }
  cmd->add_flag("--push-to-talk", flags.push_to_talk,
                "With --dialogue and --out window: the character hears only what is said between two presses of the "
                "space bar (the HUD shows whether it listens); without it, it listens by voice activity");
}

void ApplyDialogueFlags(const DialogueFlags& flags, bool window_output, SessionOptions& options) {
  if (flags.dialogue.empty() && !flags.mic.empty()) throw CommandError("--mic needs --dialogue: what would it answer?", 2);
  if (flags.dialogue.empty() && !flags.audio_in.empty())
    throw CommandError("--audio-in needs --dialogue: what would it answer?", 2);
  const bool hears = !flags.mic.empty() || !flags.audio_in.empty();
  if (flags.push_to_talk && !hears)
    throw CommandError(std::string("--push-to-talk needs something to hear: ") +
                           (flags.dialogue.empty() ? "--dialogue and " : "") + "--mic (run) or --audio-in (replay)",
                       2);
  if (flags.push_to_talk && !window_output)
    throw CommandError("--push-to-talk needs --out window: its key (space) is pressed in the window", 2);
  options.dialogue.dialogue_file = flags.dialogue;
  options.dialogue.push_to_talk = flags.push_to_talk;
  options.dialogue.mic_device = flags.mic;
  options.dialogue.audio_in = flags.audio_in;
}

}  // namespace arview::app
