#pragma once
// A scripted spoken exchange with the built-in figure through the session's dialogue, for the
// end-to-end test (tests/dialogue_session_test.cpp) and the turn-taking benchmark
// (app/session/bench_dialogue_turns.cpp): the user's side synthesized with a Flite voice into a
// WAV (silence, a line, silence, ...; each line's end known), heard through SessionDialogue as
// `replay --dialogue --audio-in` hears it (the WAV paced by the frame clock), while frames at
// 30 fps are animated with the viewer standing in front of the figure, looking at it. The frame
// clock runs `speed` times faster than the wall clock (1: real time, what the latency needs).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "app/pipeline/ar_compositor.h"
#include "app/session/character_setup.h"
#include "app/session/session_dialogue.h"
#include "audio/wav.h"
#include "figure/humanoid.h"
#include "speech/synthesizer.h"

namespace arview::app::testing {

inline const std::filesystem::path kPocketsphinxModel = "/usr/share/pocketsphinx/model/en-us/en-us/mdef";

// The user's side of the spoken guide (docs/examples/spoken-dialogue.yaml) and the machines that
// answer, in order: the greeting the viewer's approach starts, then one per line.
inline const std::vector<std::string> kUserLines = {"what is this place", "you are very kind", "how are you",
                                                    "what is your name", "i like it", "goodbye"};
inline const std::vector<std::string> kAnsweringMachines = {"welcome", "welcome", "feelings", "questions",
                                                            "questions", "welcome", "farewell"};
inline std::filesystem::path SpokenDialogue(const std::filesystem::path& source_dir) {
  return source_dir / "docs/examples/spoken-dialogue.yaml";
}

struct UserSide {
  std::vector<std::int16_t> samples;  // 16 kHz mono
  std::vector<double> line_end_s;     // where each line's speech ends in the WAV
};

// Each line after `gap_s` of silence (the first after `first_s`), then `gap_s` more.
inline UserSide SynthesizeUserSide(const std::vector<std::string>& lines, speech::Voice voice, double first_s = 3.0,
                                   double gap_s = 3.5) {
  const speech::Synthesizer synthesizer(voice);
  UserSide side;
  side.samples.assign(static_cast<std::size_t>(first_s * audio::kSpeechRate), 0);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (i > 0) side.samples.resize(side.samples.size() + static_cast<std::size_t>(gap_s * audio::kSpeechRate), 0);
    const speech::SpokenLine spoken = synthesizer.Synthesize(lines[i]);
    side.samples.insert(side.samples.end(), spoken.samples.begin(), spoken.samples.end());
    side.line_end_s.push_back(static_cast<double>(side.samples.size()) / audio::kSpeechRate);
  }
  side.samples.resize(side.samples.size() + static_cast<std::size_t>(gap_s * audio::kSpeechRate), 0);
  return side;
}

inline void WriteSpeechWav(const std::filesystem::path& file, const std::vector<std::int16_t>& samples) {
  audio::PcmAudio pcm;
  pcm.samples = samples;
  audio::WriteWav(file, pcm);
}

// The figure at the map's origin facing +Z, as a scene without lines builds it.
inline authoring::CharacterSpec FigureForDialogue(const std::string& voice) {
  figure::RegisterBuiltinCharacters();
  const std::string yaml =
      "characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n"
      "    keys: [{azimuth: 0, generate: lookat}, {azimuth: 90, generate: lookat}, {azimuth: 180, generate: lookat},"
      " {azimuth: 270, generate: lookat}]\n    gaze: {seed: 3}\n    voice: " + voice + "\n";
  return authoring::ParseScene(yaml, "dialogue-exchange.yaml").characters.at(0);
}

struct ExchangeRun {
  std::vector<DialogueTurnRecord> turns;
  std::vector<speech::Utterance> utterances;  // every reply said, its samples included
  std::vector<std::string> problems;
  std::vector<double> expression_weight;      // per frame
  std::vector<double> joy;                    // per frame
  std::vector<std::string> results;           // every recognition: "12.30 s: \"text\" 0.123 taken|not taken"
  std::vector<std::string> talk_hud;          // per frame, the HUD's push-to-talk line ("" without push-to-talk)
  bool ended = false;
};

// Runs frames until the conversation ended and every reply started (or `max_s` of frame time).
// `before_frame` (optional) is called with each frame's time before it is animated (a key pressed).
inline ExchangeRun RunExchange(const std::filesystem::path& dialogue_file, const std::filesystem::path& wav,
                               const std::string& figure_voice, double speed, double max_s, std::uint64_t seed = 7,
                               DialogueSessionOptions o = {},
                               const std::function<void(double, SessionDialogue&)>& before_frame = {}) {
  const authoring::AnimatedCharacter character(FigureForDialogue(figure_voice));
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(character);
  ExchangeRun run;
  o.dialogue_file = dialogue_file;
  o.audio_in = wav;
  o.seed = seed;
  SessionDialogue session(o, character, *animator, [&run](const speech::Utterance& u) { run.utterances.push_back(u); },
                          [&run](const std::string& line) { run.problems.push_back(line); });
  const Eigen::Vector3d eye(0.2, 1.6, 1.5);  // 1.5 m in front of the figure, at eye height
  const Eigen::Vector3d axis = (Eigen::Vector3d(0, 1.2, 0) - eye).normalized();
  constexpr double kFrame = 1.0 / 30;
  session.Start();
  const auto wall_start = std::chrono::steady_clock::now();
  for (int k = 0; k * kFrame < max_s; ++k) {
    const double t = k * kFrame;
    std::this_thread::sleep_until(wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                   std::chrono::duration<double>(t / speed)));
    if (before_frame) before_frame(t, session);
    animator->Update(eye, t, axis);
    const CharacterDialogue& d = *animator->dialogue();
    run.expression_weight.push_back(d.frame().expression_weight);
    const std::vector<std::string> hud = DialogueHudLines(d);
    run.talk_hud.push_back(d.frame().push_to_talk && hud.size() > 2 ? hud[1] : "");
    if (d.frame().heard_this_frame) {
      char line[256];
      std::snprintf(line, sizeof line, "%.2f s: \"%s\" %.3f %s", t, d.frame().heard_now.c_str(), d.frame().heard_confidence,
                    d.frame().heard_accepted ? "taken" : "not taken");
      run.results.push_back(line);
    }
    run.joy.push_back(d.manager().emotions().Intensity(dialogue::Emotion::kJoy));
    const bool all_said = !d.turns().empty() && d.turns().back().reply_start_s >= 0 &&
                          animator->speech()->saying().empty();
    if (d.manager().ended() && all_said) break;
  }
  session.Stop();
  const CharacterDialogue& d = *animator->dialogue();
  run.turns = d.turns();
  run.problems.insert(run.problems.end(), d.problems().begin(), d.problems().end());
  run.ended = d.manager().ended();
  return run;
}

}  // namespace arview::app::testing
