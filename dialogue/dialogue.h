#pragma once
// The dialogue manager (thesis §5.1.3): the dialogue units of a Dialogue running in parallel, the
// character's emotional state (§5.2), and what the viewer does as input besides what was heard.
// Each Update is one tick of the thesis's kernel, repeated while a machine can fire:
//
//   W = the machines that can make a transition, of the highest priority among them;
//   if the selected machine F_s can make a transition and is strong, W = {F_s};
//   F_s = a machine of W chosen at random (seeded); it makes its first transition that can fire.
//
// The heard text is taken by the first transition that hears it; transitions without a `heard`
// condition (the thesis's λ-transitions) fire on any update whose conditions hold. Not thread
// safe: one thread calls everything (the session's dialogue thread, or `arview dialogue chat`).

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "dialogue/dialogue_file.h"
#include "dialogue/emotion.h"

namespace arview::dialogue {

// Transitions one Update may make before the manager decides the machines go round in circles
// (through variables or emotions: a cycle without conditions is refused when the file is read).
inline constexpr int kMaxTransitionsPerUpdate = 64;

struct DialogueInput {
  double dt_s = 0;                   // time since the last update (the emotions decay over it)
  std::optional<std::string> heard;  // what the viewer said, when a phrase ended this update
  ViewerInput viewer;
};

// One transition made.
struct DialogueStep {
  std::string machine;
  std::string from;
  std::string to;
  bool took_heard = false;            // this transition consumed the heard text
  std::vector<std::string> said;      // say actions, markup with $n and ${variable} filled in
  std::vector<std::string> gestures;  // gesture actions' names
};

struct DialogueTurn {
  std::vector<DialogueStep> steps;  // in the order they were made
  bool heard_taken = false;         // some transition took the heard text
  bool ended = false;               // an `end` action ran: the conversation is over
};

class DialogueManager {
 public:
  // Every machine in its start state, the emotions at 0, the variables at their initial values.
  explicit DialogueManager(Dialogue dialogue, std::uint64_t seed = 0);

  // Throws DialogueError for a dt that is negative or not finite, or when the machines make
  // more than kMaxTransitionsPerUpdate transitions in one update (naming the machine and state).
  DialogueTurn Update(const DialogueInput& input);

  // The patterns (with `*`) that the machines can hear next: those of the transitions out of
  // each running machine's state, highest priority first, each once. What the recogniser's
  // grammar is built from. Empty once the conversation ended.
  std::vector<std::string> ExpectedPhrases() const;

  const Dialogue& dialogue() const { return dialogue_; }
  const EmotionalState& emotions() const { return emotions_; }
  // The dominant emotion, the face's expression, the disc and the activation now.
  EmotionSummary EmotionNow() const { return Summarize(emotions_); }
  // The machine that made the last transition ("" before any).
  std::string SelectedMachine() const;
  // A machine's current state ("" for an unknown machine); a finished one stays in its final state.
  std::string StateOf(std::string_view machine) const;
  bool Finished(std::string_view machine) const;
  // A variable's value (nothing for an unknown name).
  std::optional<std::string> Variable(std::string_view name) const;
  bool ended() const { return ended_; }

 private:
  struct Running {
    std::size_t state = 0;
    double seconds_in_state = 0;
    bool finished = false;  // a non-cyclic machine that reached a final state
  };
  struct Enabled {
    std::size_t machine = 0;
    std::size_t transition = 0;
    std::vector<std::string> captures;
  };

  std::optional<Enabled> FirstEnabled(std::size_t machine, const DialogueInput& input, bool heard_available) const;
  bool Holds(const Condition& c, const Running& run, const DialogueInput& input, bool heard_available,
             std::vector<std::string>& captures) const;
  DialogueStep Fire(const Enabled& enabled, DialogueTurn& turn);
  std::string Fill(const std::string& text, const std::vector<std::string>& captures) const;

  Dialogue dialogue_;
  EmotionalState emotions_;
  std::vector<Running> running_;
  std::vector<std::string> values_;  // per dialogue_.variables
  std::optional<std::size_t> selected_;
  bool ended_ = false;
  std::mt19937_64 random_;
};

}  // namespace arview::dialogue
