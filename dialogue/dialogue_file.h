#pragma once
// Dialogue files (docs/dialogue.md, "The file"): the character's personality, its emotions'
// decay, its variables, and the dialogue units of the thesis (§5.1): small machines that run in
// parallel, each with a priority, `cyclic` (back to its start state when it reaches a final one)
// and `strong` (keeps the conversation once chosen, as long as it can make a transition). A
// transition fires when all its conditions hold and runs its actions in order.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dialogue/emotion.h"
#include "dialogue/pattern.h"

namespace arview::dialogue {

// The version this reader understands (the file's `dialogue:` key).
inline constexpr int kDialogueFormatVersion = 1;
// Dialogue files are hand-written, a few kilobytes; 1 MiB is thousands of transitions.
inline constexpr std::size_t kMaxDialogueFileBytes = 1u << 20;

// What the tracker says of the viewer in an update (the camera is the viewer's eye).
struct ViewerInput {
  bool tracked = false;            // false: the tracker lost the camera; nothing below is known
  double distance_m = 0;           // from the character, along the floor (the map's unit)
  bool in_front = true;            // on the character's front half (the side it faces)
  bool gaze_on_character = false;  // the camera looks at the character
};

enum class Side { kFront, kBehind };
constexpr auto EnumNames(Side) { return EnumTable<Side, 2>{{{Side::kFront, "front"}, {Side::kBehind, "behind"}}}; }

// One condition; `kind` says which fields are used.
struct Condition {
  enum class Kind {
    kHeard,           // patterns: any of them matches what was heard
    kAboveThreshold,  // emotion > value
    kBelowThreshold,  // emotion < value
    kVariableEquals,  // variable == text
    kVariableDiffers, // variable != text
    kInStateLongerThan,  // seconds in the current state > value
    kViewerCloserThan,   // tracked and distance < value (metres)
    kViewerFartherThan,  // tracked and distance > value
    kViewerSide,         // tracked and on `side` of the character
    kViewerGaze,         // tracked and gaze on the character == flag
    kViewerTracked,      // tracking == flag (false: the tracker lost the camera)
  };
  Kind kind = Kind::kHeard;
  std::vector<Pattern> patterns;
  Emotion emotion = Emotion::kJoy;
  double value = 0;
  std::string variable;
  std::string text;
  Side side = Side::kFront;
  bool flag = true;
  int line = 0;
};

// Whether a viewer condition (kViewer*) holds for `viewer`; nothing for the other kinds.
std::optional<bool> ViewerConditionHolds(const Condition& condition, const ViewerInput& viewer);

struct Action {
  enum class Kind {
    kSay,                 // text: the speech markup, $1..$9 and ${variable} filled in
    kEmotionalInfluence,  // emotion, value in [0,1]
    kGesture,             // text: the gesture's name
    kSet,                 // variable = text ($1..$9 and ${variable} filled in)
    kEnd,                 // the conversation ends
  };
  Kind kind = Kind::kSay;
  std::string text;
  std::string variable;
  Emotion emotion = Emotion::kJoy;
  double value = 0;
  int line = 0;
};

struct Transition {
  std::size_t from = 0;  // state indices into Machine::states
  std::size_t to = 0;
  std::vector<Condition> conditions;  // all must hold; none: a λ-transition
  std::vector<Action> actions;
  int line = 0;
  // The most wildcards of its heard patterns ($n beyond every pattern's count is refused).
  std::size_t Captures() const;
  bool Hears() const;
};

struct Machine {
  std::string name;
  int priority = 0;  // >= 0; higher is chosen first
  bool cyclic = false;
  bool strong = false;
  std::vector<std::string> states;  // states[start] is where it begins
  std::size_t start = 0;
  std::vector<bool> final;          // per state: reaching it finishes the machine
  std::vector<Transition> transitions;  // in file order: the first that can fire does
  int line = 0;
};

struct Variable {
  std::string name;
  std::string initial;
};

struct Dialogue {
  std::string file;  // as given, for messages
  Personality personality{};
  double decay_per_s = 0;
  std::vector<Variable> variables;
  std::vector<Machine> machines;
};

// Parses and validates a dialogue. Every problem is a DialogueError whose message is one line
// naming the file and line, the machine and the state where there is one: a YAML error, an
// unknown key, action, condition, emotion or trait, a value out of range, a pattern that cannot
// compile, a state, variable or capture ($n) that is not defined, and a cycle of transitions that
// wait for nothing but the viewer, who can stand where all of them hold (a strong machine on it
// would never release the conversation; any machine on it would never wait for anything).
Dialogue ParseDialogue(std::string_view text, const std::string& file);
// The file read (a regular file of at most kMaxDialogueFileBytes) and parsed.
Dialogue LoadDialogue(const std::filesystem::path& path);

// What `arview dialogue check` reports besides the loader's errors.
struct CheckFinding {
  std::string machine;
  std::string state;
  std::string what;  // the whole line, naming the file, the machine and the state
  bool error = true; // unreachable states are errors (check exits 1); unused variables are not
};
// States that no path of transitions from the machine's start reaches, and variables declared
// but never read or set.
std::vector<CheckFinding> CheckDialogue(const Dialogue& dialogue);
// `arview dialogue check`: the file read as LoadDialogue reads it, except that every undefined
// name (a state, a variable, a capture $n) is a finding, not only the first; when there is none,
// CheckDialogue's findings. Every other problem is thrown as LoadDialogue throws it.
std::vector<CheckFinding> CheckDialogueFile(const std::filesystem::path& path);

}  // namespace arview::dialogue
