#pragma once
// The demo's short scripted exchange (issue 54): a visitor, spoken by a Flite voice other than the
// character's, asks two questions during the replayed lap; the character hears them through the
// session's recognizer (`replay --dialogue --audio-in` as the demo runs it) and its dialogue
// answers each with speech, a gesture and an emotion that its face shows.
//
// The dialogue is built into the binary, as the demo's scene is: the demo runs from any folder
// with nothing but the binary (docs/examples/ is not installed), and what it shows does not
// change when an example file is edited. Both files are written into the work folder, beside
// scene.yaml, so that the exchange can be read, replayed and changed there (docs/app.md).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "speech/synthesizer.h"

namespace arview::app {

// What the visitor says, when (seconds into visitor.wav, whose sample 0 is the replay's first
// frame), and which machine answers it.
struct VisitorLine {
  double start_s;
  std::string text;
};

// The figure speaks with slt (the scene's default voice); the visitor with rms, a man's voice.
inline constexpr speech::Voice kVisitorVoice = speech::Voice::kRms;
inline constexpr const char* kDemoDialogueMachine = "visitor";

// Two questions: the first after the greeting the scene's start line says (about 3.5 s), the
// second when that answer is over (about 10 s).
const std::vector<VisitorLine>& VisitorLines();

// The dialogue file's text (docs/dialogue.md): one strong machine, listening → shown → thanked.
std::string_view DemoDialogueText();

struct VisitorAudio {
  std::vector<std::int16_t> samples;  // 16 kHz mono, silence between the lines and 1 s after the last
  std::vector<double> line_end_s;     // where each line's speech ends
};

// The visitor's lines synthesized at their times. Throws speech::SpeechError.
VisitorAudio SynthesizeVisitor();

struct DemoExchange {
  std::filesystem::path dialogue;  // <work>/dialogue.yaml
  std::filesystem::path wav;       // <work>/visitor.wav
  std::vector<double> line_end_s;
};

// Writes both files (each whole or not at all). Throws Error naming the file.
DemoExchange WriteDemoExchange(const std::filesystem::path& work);

}  // namespace arview::app
