#pragma once
// `--dialogue d.yaml` for `run` and `replay` (issue 54: the character listens and answers), with
// what it listens to: `--mic DEVICE` for `run` (an ALSA capture device), `--audio-in talk.wav`
// for `replay` (a WAV heard as the frames' clock reaches each sample). The session's side:
// app/session/session_dialogue.h.

#include <CLI/CLI.hpp>

#include <string>

#include "app/cli/commands.h"
#include "app/session/ar_session.h"

namespace arview::app {

struct DialogueFlags {
  std::string dialogue;  // the dialogue file
  std::string mic;       // run: the capture device; empty: not listening
  std::string audio_in;  // replay: the WAV
  bool push_to_talk = false;  // listen only between two presses of the window's key
};

enum class DialogueInput { kMicrophone, kWavFile };

// Adds --dialogue and, by `input`, --mic (run) or --audio-in (replay) to `cmd`.
void AddDialogueFlags(CLI::App* cmd, DialogueFlags& flags, DialogueInput input);
// SessionOptions::dialogue from the flags; --mic or --audio-in without --dialogue, and
// --push-to-talk without something to hear or without a window (`window_output`: --out window) to
// press its key in, are usage errors (CommandError, status 2).
void ApplyDialogueFlags(const DialogueFlags& flags, bool window_output, SessionOptions& options);

}  // namespace arview::app
