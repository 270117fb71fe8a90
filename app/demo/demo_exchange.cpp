#include "app/demo/demo_exchange.h"

#include "audio/wav.h"
#include "base/atomic_file.h"

namespace arview::app {

namespace {

constexpr double kAfterLastLine = 1.0;  // seconds of silence after the last question

// Every phrase is whole (docs/examples/spoken-dialogue.yaml says why a lone "*" is not heard
// well); each state hears two phrases, the visitor says the first.
constexpr std::string_view kDialogue = R"(# arview demo's scripted exchange (issue 54), written by 'arview demo' from the binary.
# A visitor (visitor.wav, Flite's rms voice) asks two questions while the second lap is replayed;
# the character (slt) answers each. Format: docs/dialogue.md. Replay it:
#   arview replay <work>/walk --map <work>/map --scene <work>/scene.yaml --frames 670-1339 \
#     --dialogue <work>/dialogue.yaml --audio-in <work>/visitor.wav --out exchange.mp4
dialogue: 1
personality:
  openness: 0.8
  conscientiousness: 0.6
  extraversion: 0.7
  agreeableness: 0.8
  neuroticism: 0.2
decay: 0.02
machines:
  - name: visitor
    priority: 1
    strong: true
    states: [listening, shown, thanked]
    final: [thanked]
    transitions:
      - from: listening
        to: shown
        when:
          - heard: ["what is this place", "where am i"]
        do:
          - say: <face expr="surprised" intensity="0.6"/>You do not know? <gesture name="Point"/>This is your own room, mapped from one video.
          - emotional_influence: {emotion: surprise, value: 0.6}
      - from: shown
        to: thanked
        when:
          - heard: ["you are very kind", "thank you"]
        do:
          - say: <face expr="happy" intensity="0.8"/>Thank you! That is kind of you.
          - emotional_influence: {emotion: joy, value: 0.6}
          - emotional_influence: {emotion: gratitude, value: 0.6}
          - end
)";

}  // namespace

const std::vector<VisitorLine>& VisitorLines() {
  static const std::vector<VisitorLine> lines = {{4.5, "what is this place"}, {11.5, "you are very kind"}};
  return lines;
}

std::string_view DemoDialogueText() { return kDialogue; }

VisitorAudio SynthesizeVisitor() {
  const speech::Synthesizer synthesizer(kVisitorVoice);
  VisitorAudio audio;
  for (const VisitorLine& line : VisitorLines()) {
    const auto start = static_cast<std::size_t>(line.start_s * audio::kSpeechRate);
    audio.samples.resize(std::max(audio.samples.size(), start), 0);
    const speech::SpokenLine spoken = synthesizer.Synthesize(line.text);
    audio.samples.insert(audio.samples.end(), spoken.samples.begin(), spoken.samples.end());
    audio.line_end_s.push_back(static_cast<double>(audio.samples.size()) / audio::kSpeechRate);
  }
  audio.samples.resize(audio.samples.size() + static_cast<std::size_t>(kAfterLastLine * audio::kSpeechRate), 0);
  return audio;
}

DemoExchange WriteDemoExchange(const std::filesystem::path& work) {
  DemoExchange exchange{work / "dialogue.yaml", work / "visitor.wav", {}};
  WriteFileAtomically(exchange.dialogue, DemoDialogueText());
  VisitorAudio visitor = SynthesizeVisitor();
  audio::PcmAudio pcm;
  pcm.samples = std::move(visitor.samples);
  WriteFileAtomically(exchange.wav, audio::EncodeWav(pcm, exchange.wav.string()));
  exchange.line_end_s = std::move(visitor.line_end_s);
  return exchange;
}

}  // namespace arview::app
