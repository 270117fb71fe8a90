#pragma once
// Speech recognition on a thread of its own (docs/listen.md): 16 kHz mono int16 blocks in,
// recognitions out, through queues; the shape of docs/architecture.md's threads (a member
// std::jthread, its stop_token, nothing held across a callback).
//
// Threads: Push, StartUtterance, StopUtterance and Listen may be called from any threads (the
// audio capture thread pushes, a key handler starts and stops, the dialogue sets the phrases):
// each holds the input queue's lock only to append. TakeResult and Statistics are for any
// thread and hold the result lock only to move a result out. None of them waits for decoding,
// so the frame path never waits for recognition. The worker thread alone owns the decoder.
// The destructor stops the worker: an utterance in progress is dropped.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "listen/decoder.h"
#include "listen/voicing.h"

namespace arview::listen {

enum class ListenMode {
  kPushToTalk,     // utterances from StartUtterance to StopUtterance; audio outside them is skipped
  kVoiceActivity,  // PocketSphinx's voice-activity detector starts and ends utterances
};

struct RecognizerOptions {
  ListenMode mode = ListenMode::kPushToTalk;
  DecoderOptions decoder;  // model, dictionary, the detector's end-of-speech wait, the wake threshold
  // Results below this confidence (Hypothesis::confidence) are not accepted: noise, music and
  // speech outside the grammar forced onto it score low (docs/listen.md, "Confidence").
  double min_confidence = 0.06;
  // Results whose words last longer than this per phone, on average, are not accepted: a
  // grammar forced onto noise stretches a word over seconds; the test data's speech runs 0.07 to
  // 0.25 s per phone (a pause inside a phrase counts with its words).
  double max_seconds_per_phone = 0.4;
  // Results whose words' audio is voiced (voicing.h) in fewer than this share of its frames are
  // not accepted: hiss and rumble forced onto a grammar have no pitch.
  double min_voiced_fraction = 0.1;
  // Results whose pitch holds still to the sample for longer than this are not accepted: a held
  // note's period does not move, a voice's drifts.
  double max_steady_pitch_s = 0.12;
  // The words a `*` may stand for; empty: the wildcard_vocabulary_size most probable words of
  // the language model below that the dictionary knows.
  std::vector<std::string> wildcard_words;
  std::filesystem::path language_model = "/usr/share/pocketsphinx/model/en-us/en-us.lm.bin";
  std::size_t wildcard_vocabulary_size = 500;
  // Voice activity only: when not empty, recognition waits for this phrase (keyword spotting)
  // and then takes utterances as commands until one is accepted or wake_window_s has passed
  // since the phrase.
  std::string wake_phrase;
  double wake_window_s = 6.0;
  // Input waiting for the worker, at most; a block that would go beyond is dropped and counted.
  double max_queued_s = 10.0;
};

enum class HeardKind { kCommand, kWakePhrase };

struct HeardWord {
  std::string word;
  std::int64_t start_sample = 0;  // in the input's sample clock (samples pushed before, + 1)
  std::int64_t end_sample = 0;    // exclusive
};

struct Recognition {
  HeardKind kind = HeardKind::kCommand;
  std::string text;               // the words heard, lowercase; empty when nothing matched
  std::vector<HeardWord> words;
  double confidence = 0;          // (0, 1]: see Hypothesis::confidence (0 for a wake phrase)
  double posterior = 0;           // PocketSphinx's lattice posterior
  double seconds_per_phone = 0;   // the words' length over their phones
  double voiced_fraction = 0;     // MeasureVoicing of the words' audio
  double steady_pitch_s = 0;      // its longest_steady_pitch_s
  // Commands: text not empty and confidence ≥ min_confidence; both kinds: seconds_per_phone ≤
  // max_seconds_per_phone, voiced_fraction ≥ min_voiced_fraction, steady_pitch_s ≤
  // max_steady_pitch_s. A wake phrase not accepted does not open the wake window.
  bool accepted = false;
  // The utterance's speech in the input's sample clock: its first word's start and last word's
  // end (an utterance without words: where it began and ended).
  std::int64_t start_sample = 0;
  std::int64_t end_sample = 0;
  // The input's position when the utterance ended (StopUtterance, or the detector's end of
  // speech), and the wall time the result was made.
  std::int64_t ended_at_sample = 0;
  std::chrono::steady_clock::time_point made_at;
};

struct RecognizerStatistics {
  std::int64_t samples_pushed = 0;
  std::int64_t samples_dropped = 0;    // pushed while max_queued_s was already waiting
  std::int64_t samples_decoded = 0;
  std::int64_t utterances = 0;
  std::int64_t accepted = 0;
  std::int64_t wake_phrases = 0;       // accepted ones
  std::int64_t results_dropped = 0;    // the oldest results, when kMaxResults were not taken
  double decode_seconds = 0;           // the worker's wall time in the decoder
  double decode_cpu_seconds = 0;       // the worker thread's CPU time in it
  std::string error;                   // the worker's failure (it stops decoding), else empty
};

class Recognizer {
 public:
  // Loads the model (throws ListenError naming what is missing); `patterns` (grammar.h) are
  // the first phrases to listen for; a bad pattern or a word the dictionary lacks throws.
  Recognizer(RecognizerOptions options, const std::vector<std::string>& patterns);
  ~Recognizer();
  Recognizer(const Recognizer&) = delete;
  Recognizer& operator=(const Recognizer&) = delete;

  // Mono int16 samples at 16 kHz, in order. false (nothing queued, the samples counted as
  // dropped, the sample clock still advanced) when max_queued_s of input is already waiting.
  bool Push(std::span<const std::int16_t> samples);
  // Push-to-talk: the utterance spans the samples pushed between the two calls.
  void StartUtterance();
  void StopUtterance();
  // The phrases for the next utterance on (grammar.h). Checked on the caller's thread: a bad
  // pattern or a word the dictionary lacks throws ListenError and nothing changes. The worker
  // compiles it at the next utterance boundary (between utterances, never inside one).
  void Listen(const std::vector<std::string>& patterns);
  // The same with a JSGF grammar's text (a grammar file: PocketSphinx's test data, a power
  // user's grammar): its syntax and its words are checked here, as above.
  void ListenJsgf(const std::string& jsgf);

  // Results not taken are kept up to kMaxResults; beyond, the oldest is dropped and counted.
  static constexpr std::size_t kMaxResults = 64;
  std::optional<Recognition> TakeResult();
  // Blocks until a result is ready or `timeout` passes: for tests and tools, not the frame path.
  std::optional<Recognition> WaitResult(std::chrono::milliseconds timeout);
  // Blocks until every input pushed so far has been decoded (tests and benchmarks).
  void Drain();
  RecognizerStatistics Statistics() const;
  const std::vector<std::string>& WildcardWords() const { return wildcard_words_; }

 private:
  struct Audio {
    std::vector<std::int16_t> samples;
    std::int64_t first_sample;
  };
  struct Start {
    std::int64_t at_sample;
  };
  struct Stop {
    std::int64_t at_sample;
  };
  struct Grammar {
    std::string jsgf;
  };
  using Input = std::variant<Audio, Start, Stop, Grammar>;

  void Enqueue(Input input);
  void Run(std::stop_token stop);
  void Handle(const Audio& audio);
  void Handle(const Start& start);
  void Handle(const Stop& stop);
  void Handle(Grammar& grammar);
  void DecodeVoiceActivity(std::span<const std::int16_t> samples, std::int64_t first_sample);
  void BeginUtterance(std::int64_t at_sample);
  bool FinishUtterance(std::int64_t at_sample, HeardKind kind);  // whether accepted
  void RestartVoiceActivity(std::int64_t at_sample);
  void ApplyPendingGrammar();
  void Publish(Recognition recognition);
  void KeepAudio(std::span<const std::int16_t> samples, std::int64_t first_sample);
  Voicing VoicingOf(std::int64_t start_sample, std::int64_t end_sample) const;
  void CheckWords(const std::vector<std::string>& words, const std::string& where) const;
  std::string CheckedJsgf(const std::vector<std::string>& patterns) const;

  const RecognizerOptions options_;
  Decoder decoder_;                        // the worker's alone after construction
  std::vector<std::string> wildcard_words_;

  // Worker state.
  bool listening_ = false;                 // push-to-talk: between Start and Stop
  std::int64_t position_ = 0;              // the input's sample after the last one handled
  std::int64_t utterance_start_ = 0;       // sample where the decoder's utterance began
  bool in_speech_ = false;
  bool failed_ = false;                    // the decoder threw: input is dropped from then on
  std::int64_t awake_until_ = -1;          // wake phrase heard: commands taken until this sample
  std::string pending_grammar_;            // compiled at the next utterance boundary
  std::vector<std::int16_t> audio_;        // the utterance's input, for the voicing check
  std::int64_t audio_first_sample_ = 0;    // the input's sample of audio_[0]

  mutable std::mutex input_mutex_;
  std::condition_variable_any input_ready_;
  std::deque<Input> inputs_;
  std::int64_t queued_samples_ = 0;
  std::int64_t clock_ = 0;                 // samples pushed (and dropped) so far
  bool busy_ = false;                      // the worker is handling an input
  std::condition_variable idle_;

  mutable std::mutex result_mutex_;
  std::condition_variable result_ready_;
  std::deque<Recognition> results_;
  RecognizerStatistics statistics_;

  std::jthread worker_;  // last: started once everything it uses exists
};

}  // namespace arview::listen
