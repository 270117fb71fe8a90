#pragma once
// `arview dialogue chat`: a conversation typed in a terminal, for authoring (no audio, no camera).
// Each line read is what the character heard; the replies come back as "<machine>: <markup>"
// lines, then one line with the selected machine and the emotional state. Lines starting with
// '/' are commands (docs/dialogue.md, "arview dialogue chat"):
//   /wait S            S seconds pass with nothing heard (time conditions, decay)
//   /viewer WORDS      the viewer: a distance in metres, front|behind, gaze|no-gaze, lost|tracked
//   /expect            the phrases the dialogue can hear next
//   /emotions          every emotion above 0
//   /quit              the end (as the end of the input)

#include <istream>
#include <ostream>

#include "dialogue/dialogue.h"

namespace arview::dialogue {

struct ChatOptions {
  double seconds_per_line = 1.0;  // dialogue time that passes with each line typed
  bool prompt = false;            // print "> " before reading (a terminal)
  ViewerInput viewer{true, 1.5, true, true};  // until /viewer says otherwise: close, in front, looking
};

// Runs until the input ends, /quit, or an `end` action. A bad command is one line on `out` and
// the chat goes on; a DialogueError from the manager ends it (thrown).
void RunChat(DialogueManager& manager, std::istream& in, std::ostream& out, const ChatOptions& options);

// The line printed after each turn: "[greeting] joy 0.42 -> happy 0.42, activation 0.21".
std::string StatusLine(const DialogueManager& manager);

}  // namespace arview::dialogue
