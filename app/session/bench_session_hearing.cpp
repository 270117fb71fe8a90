// What the session hears (issue 54), through the whole session path rather than listen/ alone: a
// WAV paced by the frame clock as `replay --dialogue --audio-in` paces it, the recognizer in the
// session's mode and grammar (the dialogue's phrases, from ExpectedPhrases), its gates, and the
// dialogue's transitions (test_dialogue_exchange.h's RunExchange). docs/listen.md, "In the session".
//
//   ARVIEW_SOURCE_DIR=$PWD build/release/app/session/bench_session --benchmark_filter='Testdata|Noise'
//
// BM_TestdataThroughSession: Debian's pocketsphinx-testdata human recordings (cards 001–005,
// goforward) in one WAV, 3 s of silence around each, heard at real time against a dialogue whose
// phrases are their grammars' (below); word accuracy against the package's transcripts.
// BM_NoiseThroughSession/0 (voice activity) and /1 (push-to-talk, the key pressed at the start of
// each segment and again at its end): five minutes of silence, noise and music (listen/'s
// generators, 10 s of each in turn) against docs/examples/spoken-dialogue.yaml at four times real
// time; "no transition" is no turn taken on something heard.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "app/session/test_dialogue_exchange.h"
#include "listen/test_listen_data.h"
#include "tests/support/test_data.h"

namespace {

using namespace arview;
namespace fs = std::filesystem;
namespace lt = listen::testing;

constexpr double kFrameRate = 30;

// A recognition as RunExchange prints it: "12.30 s: \"text\" 0.123 taken|not taken".
struct Heard {
  double time_s = 0;
  std::string text;
  bool taken = false;
};

Heard ParseResult(const std::string& line) {
  Heard h;
  h.time_s = std::stod(line);
  const auto open = line.find('"'), close = line.rfind('"');
  h.text = line.substr(open + 1, close - open - 1);
  h.taken = line.size() >= 10 && line.compare(line.size() - 10, 10, " not taken") != 0;
  return h;
}

fs::path TempFile(const std::string& name) {
  return fs::temp_directory_path() / ("arview_bench_hearing_" + std::to_string(::getpid()) + "_" + name);
}

// The phrases of cards.gram that a dialogue can list: one card (a rank, "of" or not, a suit), a
// rank and a card, two ranks: 1,876 phrases. Its two- and three-card phrases (12,544 and 1.4
// million) cannot be listed; of them only the one a recording says (005) is added, so that
// recording is heard against a grammar that holds it among the others.
std::vector<std::string> CardPhrases() {
  const std::vector<std::string> ranks = {"ace", "two", "three", "four", "five", "six", "seven",
                                          "eight", "nine", "ten", "jack", "queen", "king", "lady"};
  const std::vector<std::string> suits = {"clubs", "hearts", "diamonds", "spades"};
  std::vector<std::string> cards;
  for (const std::string& r : ranks)
    for (const std::string& s : suits) {
      cards.push_back(r + " of " + s);
      cards.push_back(r + " " + s);
    }
  std::vector<std::string> phrases = cards;
  for (const std::string& r : ranks)
    for (const std::string& c : cards) phrases.push_back(r + " " + c);
  for (const std::string& a : ranks)
    for (const std::string& b : ranks) phrases.push_back(a + " " + b);
  phrases.push_back("eight of spades four of clubs seven of hearts");
  return phrases;
}

// goforward.gram whole: "go forward ten meters", and go forward|backward one..ten [meter|meters].
std::vector<std::string> GoForwardPhrases() {
  std::vector<std::string> phrases;
  for (const char* direction : {"forward", "backward"})
    for (const char* distance : {"one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten"})
      for (const char* unit : {"", " meter", " meters"})
        phrases.push_back(std::string("go ") + direction + " " + distance + unit);
  return phrases;
}

// One cyclic machine that answers every phrase: each utterance heard right is one turn.
void WriteListeningDialogue(const fs::path& file, const std::vector<std::string>& phrases) {
  std::ofstream out(file);
  out << "dialogue: 1\n"
         "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, neuroticism: 0.5}\n"
         "decay: 0.01\n"
         "machines:\n"
         "  - name: listener\n    cyclic: true\n    states: [listening, heard]\n    final: [heard]\n"
         "    transitions:\n      - from: listening\n        to: heard\n        when:\n          - heard:\n";
  for (const std::string& p : phrases) out << "              - \"" << p << "\"\n";
  out << "        do:\n          - say: Yes.\n";
}

struct Recording {
  std::string id;
  std::vector<std::int16_t> samples;
  std::string transcript;
  double start_s = 0, end_s = 0;  // in the WAV
};

void BM_TestdataThroughSession(benchmark::State& state) {
  if (!fs::exists(lt::kTestdata / "cards" / "001.wav") || !fs::exists(lt::kModelMdef)) {
    state.SkipWithError("needs the Debian packages pocketsphinx-testdata and pocketsphinx-en-us");
    return;
  }
  const std::map<std::string, std::string> cards = lt::ReadTranscription(lt::kTestdata / "cards" / "cards.transcription");
  std::vector<Recording> recordings;
  for (const auto& [id, words] : cards) recordings.push_back({"cards/" + id, lt::LoadTestWav(lt::kTestdata / "cards" / (id + ".wav")), words});
  recordings.push_back({"goforward", lt::LoadRaw(lt::kTestdata / "goforward.raw"), "go forward ten meters"});
  constexpr double kGap = 3.0;
  std::vector<std::int16_t> wav(static_cast<std::size_t>(kGap * audio::kSpeechRate), 0);
  for (Recording& r : recordings) {
    r.start_s = static_cast<double>(wav.size()) / audio::kSpeechRate;
    wav.insert(wav.end(), r.samples.begin(), r.samples.end());
    r.end_s = static_cast<double>(wav.size()) / audio::kSpeechRate;
    wav.resize(wav.size() + static_cast<std::size_t>(kGap * audio::kSpeechRate), 0);
  }
  const fs::path wav_file = TempFile("testdata.wav"), dialogue_file = TempFile("testdata.yaml");
  app::testing::WriteSpeechWav(wav_file, wav);
  std::vector<std::string> phrases = CardPhrases();
  for (const std::string& p : GoForwardPhrases()) phrases.push_back(p);
  WriteListeningDialogue(dialogue_file, phrases);
  std::size_t words = 0, errors = 0, accepted = 0, exact = 0;
  for (auto _ : state) {
    const app::testing::ExchangeRun run = app::testing::RunExchange(dialogue_file, wav_file, "slt", 1.0,
                                                                    static_cast<double>(wav.size()) / audio::kSpeechRate);
    for (const std::string& p : run.problems) std::fprintf(stderr, "problem: %s\n", p.c_str());
    for (const Recording& r : recordings) {
      // What was heard from the recording's start to its end plus the end of speech and a frame.
      std::string heard;
      bool all_taken = true;
      for (const std::string& line : run.results) {
        const Heard h = ParseResult(line);
        if (h.time_s < r.start_s || h.time_s > r.end_s + kGap - 0.5) continue;
        heard += (heard.empty() || h.text.empty() ? "" : " ") + h.text;
        all_taken = all_taken && h.taken;
      }
      const std::size_t e = lt::WordErrors(lt::Words(r.transcript), lt::Words(heard));
      std::fprintf(stderr, "%-10s said \"%s\", heard \"%s\"%s: %zu error(s)\n", r.id.c_str(), r.transcript.c_str(),
                   heard.c_str(), heard.empty() ? "" : all_taken ? " (taken)" : " (not all taken)", e);
      words += lt::Words(r.transcript).size();
      errors += e;
      exact += e == 0;
      accepted += !heard.empty() && all_taken;
    }
  }
  fs::remove(wav_file);
  fs::remove(dialogue_file);
  state.counters["phrases"] = static_cast<double>(phrases.size());
  state.counters["words"] = static_cast<double>(words);
  state.counters["word_accuracy_pct"] = words ? 100.0 * (1.0 - static_cast<double>(errors) / static_cast<double>(words)) : 0;
  state.counters["exact"] = static_cast<double>(exact);
  state.counters["accepted"] = static_cast<double>(accepted);
}
BENCHMARK(BM_TestdataThroughSession)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_NoiseThroughSession(benchmark::State& state) {
  if (!fs::exists(lt::kModelMdef)) {
    state.SkipWithError("needs the Debian package pocketsphinx-en-us");
    return;
  }
  const bool push_to_talk = state.range(0) == 1;
  constexpr double kSegmentS = 10, kMinutes = 5, kSpeed = 4;
  const std::vector<lt::NoiseKind> kinds = lt::NoiseKinds(static_cast<std::size_t>(kSegmentS * audio::kSpeechRate));
  const auto segments = static_cast<std::size_t>(kMinutes * 60 / kSegmentS);
  std::vector<std::int16_t> wav;
  for (std::size_t i = 0; i < segments; ++i) {
    const std::vector<std::int16_t> s = kinds[i % kinds.size()].make(static_cast<std::uint32_t>(54 + i));
    wav.insert(wav.end(), s.begin(), s.end());
  }
  const fs::path wav_file = TempFile("noise.wav");
  app::testing::WriteSpeechWav(wav_file, wav);
  app::DialogueSessionOptions o;
  o.push_to_talk = push_to_talk;
  std::size_t results = 0, with_words = 0, taken = 0, heard_turns = 0, turns = 0;
  for (auto _ : state) {
    std::size_t pressed_for = 0;  // segments whose key has been pressed
    const app::testing::ExchangeRun run = app::testing::RunExchange(
        app::testing::SpokenDialogue(arview::testing::SourceDir()), wav_file, "slt", kSpeed, kMinutes * 60 + 1, 7, o,
        [&](double t, app::SessionDialogue& session) {
          if (!push_to_talk) return;
          const auto segment = static_cast<std::size_t>(t / kSegmentS);
          if (segment < pressed_for) return;
          if (pressed_for > 0) session.TogglePushToTalk();        // the key again: the last segment heard
          if (segment < segments) session.TogglePushToTalk();     // and pressed for this one
          pressed_for = segment + 1;
        });
    for (const std::string& p : run.problems) std::fprintf(stderr, "problem: %s\n", p.c_str());
    for (const std::string& line : run.results) {
      const Heard h = ParseResult(line);
      ++results;
      with_words += !h.text.empty();
      taken += h.taken;
      if (!h.text.empty()) {
        // Voice activity answers within the segment it heard; push-to-talk after the key closed
        // it, at the next boundary.
        const auto segment = push_to_talk ? static_cast<std::size_t>(std::max(0.0, std::round(h.time_s / kSegmentS) - 1))
                                          : static_cast<std::size_t>(h.time_s / kSegmentS);
        std::fprintf(stderr, "%s in %s\n", line.c_str(), kinds[std::min(segment, segments - 1) % kinds.size()].name.c_str());
      }
    }
    for (const app::DialogueTurnRecord& t : run.turns) {
      ++turns;
      heard_turns += !t.heard.empty();
    }
  }
  fs::remove(wav_file);
  state.counters["results"] = static_cast<double>(results);
  state.counters["with_words"] = static_cast<double>(with_words);
  state.counters["taken"] = static_cast<double>(taken);
  state.counters["turns"] = static_cast<double>(turns);
  state.counters["heard_turns"] = static_cast<double>(heard_turns);
}
BENCHMARK(BM_NoiseThroughSession)->DenseRange(0, 1)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
