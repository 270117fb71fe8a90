// Dialogue files through dialogue::ParseDialogue, and a manager run on what loads: a few updates
// with heard text and viewer changes. What loads must hold together: every transition's states
// are the machine's, every capture a say or set uses is defined, ExpectedPhrases compile again
// as patterns, intensities stay in [0, 1]. A refusal is a DialogueError, nothing else.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "dialogue/dialogue.h"
#include "dialogue/dialogue_file.h"

namespace {

using namespace arview::dialogue;

void Converse(const Dialogue& dialogue) {
  DialogueManager manager(dialogue, 1);
  const char* heard[] = {"hello my name is ann", "yes", "what is this place", "you are nice", "goodbye", ""};
  double dt = 0.0;
  for (const char* text : heard) {
    DialogueInput input;
    input.dt_s = dt;
    input.heard = std::string(text);
    input.viewer = {dt < 2.0, 1.0 + dt, dt < 1.5, true};
    try {
      manager.Update(input);
    } catch (const DialogueError&) {
      return;  // machines going round in circles through variables: refused at run time
    }
    for (const double e : manager.emotions().Intensities())
      if (!(e >= 0.0 && e <= 1.0)) std::abort();
    for (const std::string& phrase : manager.ExpectedPhrases()) Pattern::Compile(phrase, "fuzz");  // throws → a finding
    dt += 0.75;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Dialogue dialogue;
  try {
    dialogue = ParseDialogue(text, "fuzz.yaml");
  } catch (const DialogueError&) {
    return 0;
  }
  if (dialogue.machines.empty()) std::abort();
  for (const Machine& m : dialogue.machines) {
    if (m.states.empty() || m.start >= m.states.size() || m.final.size() != m.states.size()) std::abort();
    for (const Transition& t : m.transitions)
      if (t.from >= m.states.size() || t.to >= m.states.size()) std::abort();
  }
  for (const CheckFinding& finding : CheckDialogue(dialogue))
    if (finding.what.rfind("fuzz.yaml", 0) != 0) std::abort();  // every finding names the file
  Converse(dialogue);
  return 0;
}
