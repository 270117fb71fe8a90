#include "listen/recognizer.h"

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <sstream>
#include <utility>

#include "listen/grammar.h"
#include "listen/listen_error.h"
#include "listen/voicing.h"

namespace arview::listen {
namespace {

// Voice activity: the detector is asked after every 20 ms, so an utterance's end is seen within
// 20 ms of the detector deciding it.
constexpr std::size_t kVoiceActivityChunk = 320;

// Voice activity outside speech keeps at most this much input for the voicing check: the
// detector's 20 frames before speech, and more.
constexpr std::size_t kKeptBeforeSpeech = kSampleRate;

double ThreadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

DecoderOptions DecoderOptionsFor(const RecognizerOptions& options) {
  DecoderOptions decoder = options.decoder;
  decoder.voice_activity = options.mode == ListenMode::kVoiceActivity;
  return decoder;
}

[[noreturn]] void RefuseOption(const std::string& field, double value, const std::string& range) {
  std::ostringstream line;
  line << "listen: RecognizerOptions::" << field << " must be " << range << ", not " << value;
  throw ListenError(line.str());
}

RecognizerOptions CheckedOptions(RecognizerOptions options) {
  const auto within = [](double value, double low, double high) { return value >= low && value <= high; };
  if (!within(options.min_confidence, 0, 1)) RefuseOption("min_confidence", options.min_confidence, "in [0, 1]");
  if (!within(options.min_voiced_fraction, 0, 1)) {
    RefuseOption("min_voiced_fraction", options.min_voiced_fraction, "in [0, 1]");
  }
  if (!(options.max_seconds_per_phone > 0)) {
    RefuseOption("max_seconds_per_phone", options.max_seconds_per_phone, "above 0");
  }
  if (!(options.max_steady_pitch_s > 0)) RefuseOption("max_steady_pitch_s", options.max_steady_pitch_s, "above 0");
  if (!(options.max_queued_s > 0)) RefuseOption("max_queued_s", options.max_queued_s, "above 0");
  if (!(options.wake_window_s > 0)) RefuseOption("wake_window_s", options.wake_window_s, "above 0");
  if (options.decoder.vad_postspeech_frames < 1) {
    RefuseOption("decoder.vad_postspeech_frames", options.decoder.vad_postspeech_frames, "at least 1");
  }
  if (!(options.decoder.wake_threshold > 0)) {
    RefuseOption("decoder.wake_threshold", options.decoder.wake_threshold, "above 0");
  }
  if (options.wildcard_words.empty() && options.wildcard_vocabulary_size == 0) {
    throw ListenError("listen: RecognizerOptions::wildcard_vocabulary_size must be at least 1 when no wildcard_words are given");
  }
  return options;
}

bool HasWildcard(const std::vector<std::string>& patterns) {
  return std::any_of(patterns.begin(), patterns.end(),
                     [](const std::string& p) { return p.find('*') != std::string::npos; });
}

}  // namespace

Recognizer::Recognizer(RecognizerOptions options, const std::vector<std::string>& patterns)
    : options_(CheckedOptions(std::move(options))), decoder_(DecoderOptionsFor(options_)),
      wildcard_words_(options_.wildcard_words) {
  if (wildcard_words_.empty()) {
    wildcard_words_ = MostProbableWords(options_.language_model, options_.wildcard_vocabulary_size, decoder_);
  }
  decoder_.UseGrammar(CheckedJsgf(patterns));
  if (!options_.wake_phrase.empty()) {
    if (options_.mode != ListenMode::kVoiceActivity) {
      throw ListenError("listen: a wake phrase (\"" + options_.wake_phrase +
                        "\") needs voice-activity mode: push-to-talk's key already says when to listen");
    }
    decoder_.UseWakePhrase(options_.wake_phrase);
  }
  if (options_.mode == ListenMode::kVoiceActivity) BeginUtterance(0);
  worker_ = std::jthread([this](std::stop_token stop) { Run(stop); });
}

Recognizer::~Recognizer() {
  worker_.request_stop();
  input_ready_.notify_all();
}

void Recognizer::CheckWords(const std::vector<std::string>& words, const std::string& where) const {
  for (const std::string& word : words) {
    if (word != "*" && !decoder_.Knows(word)) {
      throw ListenError("listen: " + where + " has the word '" + word +
                        "', which the pronunciation dictionary does not have");
    }
  }
}

std::string Recognizer::CheckedJsgf(const std::vector<std::string>& patterns) const {
  for (const std::string& pattern : patterns) {
    CheckWords(PatternTokens(pattern), "the pattern \"" + pattern + "\"");
  }
  return JsgfFromPatterns(patterns, HasWildcard(patterns) ? wildcard_words_ : std::vector<std::string>{});
}

// The dictionary is only read once the decoder is set up (Knows looks a word up; the worker
// never adds words), so the callers' threads may check words while the worker decodes.
void Recognizer::Listen(const std::vector<std::string>& patterns) { Enqueue(Grammar{CheckedJsgf(patterns)}); }

void Recognizer::ListenJsgf(const std::string& jsgf) {
  CheckWords(JsgfWords(jsgf), "the grammar");
  Enqueue(Grammar{jsgf});
}

bool Recognizer::Push(std::span<const std::int16_t> samples) {
  const auto count = static_cast<std::int64_t>(samples.size());
  const auto max_queued = static_cast<std::int64_t>(options_.max_queued_s * kSampleRate);
  {
    const std::lock_guard lock(input_mutex_);
    const std::int64_t first = clock_;
    clock_ += count;
    if (queued_samples_ + count > max_queued) {
      const std::lock_guard results(result_mutex_);
      statistics_.samples_pushed += count;
      statistics_.samples_dropped += count;
      return false;
    }
    queued_samples_ += count;
    inputs_.emplace_back(Audio{{samples.begin(), samples.end()}, first});
  }
  input_ready_.notify_one();
  const std::lock_guard results(result_mutex_);
  statistics_.samples_pushed += count;
  return true;
}

void Recognizer::StartUtterance() {
  const std::lock_guard lock(input_mutex_);
  inputs_.emplace_back(Start{clock_});
  input_ready_.notify_one();
}

void Recognizer::StopUtterance() {
  const std::lock_guard lock(input_mutex_);
  inputs_.emplace_back(Stop{clock_});
  input_ready_.notify_one();
}

void Recognizer::Enqueue(Input input) {
  {
    const std::lock_guard lock(input_mutex_);
    inputs_.push_back(std::move(input));
  }
  input_ready_.notify_one();
}

std::optional<Recognition> Recognizer::TakeResult() {
  const std::lock_guard lock(result_mutex_);
  if (results_.empty()) return std::nullopt;
  Recognition result = std::move(results_.front());
  results_.pop_front();
  return result;
}

std::optional<Recognition> Recognizer::WaitResult(std::chrono::milliseconds timeout) {
  std::unique_lock lock(result_mutex_);
  if (!result_ready_.wait_for(lock, timeout, [this] { return !results_.empty(); })) return std::nullopt;
  Recognition result = std::move(results_.front());
  results_.pop_front();
  return result;
}

void Recognizer::Drain() {
  std::unique_lock lock(input_mutex_);
  idle_.wait(lock, [this] { return inputs_.empty() && !busy_; });
}

RecognizerStatistics Recognizer::Statistics() const {
  const std::lock_guard lock(result_mutex_);
  return statistics_;
}

void Recognizer::Run(std::stop_token stop) {
  pthread_setname_np(pthread_self(), "arview-listen");  // shown by top -H
  while (true) {
    Input input;
    {
      std::unique_lock lock(input_mutex_);
      if (!input_ready_.wait(lock, stop, [this] { return !inputs_.empty(); })) return;
      input = std::move(inputs_.front());
      inputs_.pop_front();
      if (const auto* audio = std::get_if<Audio>(&input)) {
        queued_samples_ -= static_cast<std::int64_t>(audio->samples.size());
      }
      busy_ = true;
    }
    if (!failed_) {
      const auto begun = std::chrono::steady_clock::now();
      const double cpu_begun = ThreadCpuSeconds();
      try {
        std::visit([this](auto& item) { Handle(item); }, input);
      } catch (const ListenError& error) {
        failed_ = true;
        const std::lock_guard lock(result_mutex_);
        statistics_.error = error.what();
      }
      const std::chrono::duration<double> spent = std::chrono::steady_clock::now() - begun;
      const double cpu_spent = ThreadCpuSeconds() - cpu_begun;
      const std::lock_guard lock(result_mutex_);
      statistics_.decode_seconds += spent.count();
      statistics_.decode_cpu_seconds += cpu_spent;
    }
    {
      const std::lock_guard lock(input_mutex_);
      busy_ = false;
      if (inputs_.empty()) idle_.notify_all();
    }
  }
}

void Recognizer::Handle(const Audio& audio) {
  position_ = audio.first_sample + static_cast<std::int64_t>(audio.samples.size());
  if (options_.mode == ListenMode::kVoiceActivity) {
    DecodeVoiceActivity(audio.samples, audio.first_sample);
  } else if (listening_) {
    KeepAudio(audio.samples, audio.first_sample);
    decoder_.Process(audio.samples);
  } else {
    return;
  }
  const std::lock_guard lock(result_mutex_);
  statistics_.samples_decoded += static_cast<std::int64_t>(audio.samples.size());
}

void Recognizer::Handle(const Start& start) {
  if (options_.mode != ListenMode::kPushToTalk || listening_) return;
  ApplyPendingGrammar();
  listening_ = true;
  BeginUtterance(start.at_sample);
}

void Recognizer::Handle(const Stop& stop) {
  if (options_.mode != ListenMode::kPushToTalk || !listening_) return;
  listening_ = false;
  FinishUtterance(stop.at_sample, HeardKind::kCommand);
}

void Recognizer::Handle(Grammar& grammar) {
  pending_grammar_ = std::move(grammar.jsgf);
  if (options_.mode == ListenMode::kPushToTalk) {
    if (!listening_) ApplyPendingGrammar();
  } else if (!in_speech_) {
    decoder_.EndUtterance();  // no speech in it yet: nothing is lost
    RestartVoiceActivity(position_);
  }
}

void Recognizer::ApplyPendingGrammar() {
  if (pending_grammar_.empty()) return;
  const std::string jsgf = std::move(pending_grammar_);
  pending_grammar_.clear();
  decoder_.UseGrammar(jsgf);
  if (decoder_.HasWakePhrase() && awake_until_ < 0) decoder_.SearchWakePhrase();
}

void Recognizer::KeepAudio(std::span<const std::int16_t> samples, std::int64_t first_sample) {
  if (audio_.empty()) audio_first_sample_ = first_sample;
  audio_.insert(audio_.end(), samples.begin(), samples.end());
  if (!in_speech_ && options_.mode == ListenMode::kVoiceActivity && audio_.size() > 2 * kKeptBeforeSpeech) {
    const std::size_t drop = audio_.size() - kKeptBeforeSpeech;
    audio_.erase(audio_.begin(), audio_.begin() + static_cast<std::ptrdiff_t>(drop));
    audio_first_sample_ += static_cast<std::int64_t>(drop);
  }
}

Voicing Recognizer::VoicingOf(std::int64_t start_sample, std::int64_t end_sample) const {
  const std::int64_t audio_end = audio_first_sample_ + static_cast<std::int64_t>(audio_.size());
  const std::int64_t first = std::clamp(start_sample, audio_first_sample_, audio_end) - audio_first_sample_;
  const std::int64_t last = std::clamp(end_sample, audio_first_sample_, audio_end) - audio_first_sample_;
  return MeasureVoicing(std::span<const std::int16_t>(audio_).subspan(
      static_cast<std::size_t>(first), static_cast<std::size_t>(last - first)));
}

void Recognizer::BeginUtterance(std::int64_t at_sample) {
  audio_.clear();
  audio_first_sample_ = at_sample;
  utterance_start_ = at_sample;
  decoder_.StartUtterance();
}

// Between two voice-activity utterances: the new grammar, the search (the wake phrase unless
// awake), and a fresh utterance.
void Recognizer::RestartVoiceActivity(std::int64_t at_sample) {
  in_speech_ = false;
  ApplyPendingGrammar();
  if (decoder_.HasWakePhrase()) {
    if (awake_until_ >= 0) {
      decoder_.SearchGrammar();
    } else {
      decoder_.SearchWakePhrase();
    }
  }
  BeginUtterance(at_sample);
}

void Recognizer::DecodeVoiceActivity(std::span<const std::int16_t> samples, std::int64_t first_sample) {
  for (std::size_t done = 0; done < samples.size(); done += kVoiceActivityChunk) {
    const std::size_t count = std::min(kVoiceActivityChunk, samples.size() - done);
    KeepAudio(samples.subspan(done, count), first_sample + static_cast<std::int64_t>(done));
    decoder_.Process(samples.subspan(done, count));
    const std::int64_t at = first_sample + static_cast<std::int64_t>(done + count);
    if (decoder_.WakePhraseSpotted()) {
      if (FinishUtterance(at, HeardKind::kWakePhrase)) {
        awake_until_ = at + static_cast<std::int64_t>(options_.wake_window_s * kSampleRate);
      }
      RestartVoiceActivity(at);
      continue;
    }
    const bool speech = decoder_.InSpeech();
    if (speech && !in_speech_) {
      in_speech_ = true;
    } else if (!speech && in_speech_) {
      const bool command = !decoder_.HasWakePhrase() || awake_until_ >= 0;
      if (command) {
        // An accepted command closes the wake window; words it refused (the end of the sentence
        // that held the wake phrase, a cough) leave it open until it runs out.
        if (FinishUtterance(at, HeardKind::kCommand)) awake_until_ = -1;
      } else {
        decoder_.EndUtterance();  // speech without the wake phrase: not for us
      }
      RestartVoiceActivity(at);
    } else if (!in_speech_ && awake_until_ >= 0 && at > awake_until_) {
      awake_until_ = -1;  // nothing said after the wake phrase: back to waiting for it
      decoder_.EndUtterance();
      RestartVoiceActivity(at);
    }
  }
}

bool Recognizer::FinishUtterance(std::int64_t at_sample, HeardKind kind) {
  const Hypothesis hypothesis = decoder_.EndUtterance();
  Recognition recognition;
  recognition.kind = kind;
  recognition.text = hypothesis.text;
  recognition.confidence = hypothesis.confidence;
  recognition.posterior = hypothesis.posterior;
  recognition.seconds_per_phone = hypothesis.frames_per_phone * kSamplesPerFrame / kSampleRate;
  for (const DecodedWord& word : hypothesis.words) {
    recognition.words.push_back({word.word, utterance_start_ + std::int64_t{word.first_frame} * kSamplesPerFrame,
                                 utterance_start_ + std::int64_t{word.last_frame + 1} * kSamplesPerFrame});
  }
  recognition.start_sample = recognition.words.empty() ? utterance_start_ : recognition.words.front().start_sample;
  recognition.end_sample = recognition.words.empty() ? at_sample : recognition.words.back().end_sample;
  recognition.ended_at_sample = at_sample;
  if (!recognition.words.empty()) {
    const Voicing voicing = VoicingOf(recognition.start_sample, recognition.end_sample);
    recognition.voiced_fraction = voicing.voiced_fraction;
    recognition.steady_pitch_s = voicing.longest_steady_pitch_s;
  }
  const bool sounds_like_a_voice = !recognition.words.empty() &&
                                   recognition.seconds_per_phone <= options_.max_seconds_per_phone &&
                                   recognition.voiced_fraction >= options_.min_voiced_fraction &&
                                   recognition.steady_pitch_s <= options_.max_steady_pitch_s;
  recognition.accepted = sounds_like_a_voice &&
                         (kind == HeardKind::kWakePhrase || recognition.confidence >= options_.min_confidence);
  const bool accepted = recognition.accepted;
  Publish(std::move(recognition));
  return accepted;
}

void Recognizer::Publish(Recognition recognition) {
  recognition.made_at = std::chrono::steady_clock::now();
  {
    const std::lock_guard lock(result_mutex_);
    ++statistics_.utterances;
    if (recognition.kind == HeardKind::kWakePhrase && recognition.accepted) ++statistics_.wake_phrases;
    if (recognition.kind == HeardKind::kCommand && recognition.accepted) ++statistics_.accepted;
    if (results_.size() == kMaxResults) {
      results_.pop_front();
      ++statistics_.results_dropped;
    }
    results_.push_back(std::move(recognition));
  }
  result_ready_.notify_all();
}

}  // namespace arview::listen
