#include "speech/synthesizer.h"

#include <flite/flite.h>

#include <array>
#include <csetjmp>
#include <cstdlib>
#include <memory>
#include <mutex>

extern "C" {
cst_voice* register_cmu_us_slt(const char* voxdir);
cst_voice* register_cmu_us_rms(const char* voxdir);
cst_voice* register_cmu_us_awb(const char* voxdir);
}

namespace arview::speech {
namespace {

// The one lock around Flite (see the header for why).
std::mutex& FliteMutex() {
  static std::mutex mutex;
  return mutex;
}

// Registers a voice on its first use; Flite keeps it until exit. Called with FliteMutex held.
cst_voice* RegisteredVoice(Voice voice) {
  static const bool initialised = (flite_init(), true);
  (void)initialised;
  switch (voice) {
    case Voice::kSlt: {
      static cst_voice* const slt = register_cmu_us_slt(nullptr);
      return slt;
    }
    case Voice::kRms: {
      static cst_voice* const rms = register_cmu_us_rms(nullptr);
      return rms;
    }
    case Voice::kAwb: {
      static cst_voice* const awb = register_cmu_us_awb(nullptr);
      return awb;
    }
  }
  return nullptr;
}

// Flite's clustergen voices draw the noise of unvoiced sounds from the C library's rand(). Each
// line's synthesis swaps in a generator of its own, started from one seed, and gives the
// caller's back after: the same line gives the same samples, and a seeded rand() elsewhere in
// the process (map/descriptor_index.cpp) keeps its sequence unless it draws while a line is
// being synthesized.
class SeededRand {
 public:
  SeededRand() : previous_(initstate(kSeed, state_.data(), state_.size())) {}
  ~SeededRand() { setstate(previous_); }
  SeededRand(const SeededRand&) = delete;
  SeededRand& operator=(const SeededRand&) = delete;

 private:
  static constexpr unsigned kSeed = 53;
  std::array<char, 256> state_{};
  char* previous_;
};

// Flite's internal errors call exit(-1) unless its global cst_errjmp points at a jump buffer
// (cst_error.h); with one, they longjmp back here and the line is refused instead of the process
// ending. Only C calls run between setjmp and its return, so the jump skips no C++ destructor.
// Called with FliteMutex held (cst_errjmp is one global).
cst_utterance* SynthesizeOrNull(const char* text, cst_voice* voice) {
  jmp_buf on_error;
  jmp_buf* const previous = cst_errjmp;
  if (setjmp(on_error) != 0) {
    cst_errjmp = previous;
    return nullptr;
  }
  cst_errjmp = &on_error;
  cst_utterance* const utterance = flite_synth_text(text, voice);
  cst_errjmp = previous;
  return utterance;
}

struct UtteranceDeleter {
  void operator()(cst_utterance* utterance) const { delete_utterance(utterance); }
};

std::string ItemName(const cst_item* item) { return item_feat_string(item, "name"); }

// Where a segment starts: where the one before it ended (Flite gives ends only).
double SegmentStart(const cst_item* segment_in_segment_relation) {
  const cst_item* previous = item_prev(segment_in_segment_relation);
  return previous != nullptr ? item_feat_float(previous, "end") : 0.0;
}

std::vector<Phone> PhonesOf(cst_utterance* utterance) {
  std::vector<Phone> phones;
  for (const cst_item* s = relation_head(utt_relation(utterance, "Segment")); s != nullptr; s = item_next(s))
    phones.push_back({ItemName(s), SegmentStart(s), item_feat_float(s, "end")});
  return phones;
}

// A word's first phone through the SylStructure relation: word → first syllable → first segment.
std::optional<double> WordStart(const cst_item* word) {
  const cst_item* in_syllables = item_as(word, "SylStructure");
  const cst_item* syllable = in_syllables != nullptr ? item_daughter(in_syllables) : nullptr;
  const cst_item* segment = syllable != nullptr ? item_daughter(syllable) : nullptr;
  const cst_item* in_segments = segment != nullptr ? item_as(segment, "Segment") : nullptr;
  if (in_segments == nullptr) return std::nullopt;
  return SegmentStart(in_segments);
}

// A token's words are its daughters in the Token relation (a number's token has several).
std::vector<SpokenToken> TokensOf(cst_utterance* utterance) {
  std::vector<SpokenToken> tokens;
  for (const cst_item* t = relation_head(utt_relation(utterance, "Token")); t != nullptr; t = item_next(t)) {
    SpokenToken token{ItemName(t), std::nullopt};
    for (const cst_item* word = item_daughter(t); word != nullptr && !token.start_s; word = item_next(word))
      token.start_s = WordStart(word);
    tokens.push_back(std::move(token));
  }
  return tokens;
}

std::vector<std::int16_t> SamplesOf(cst_utterance* utterance, Voice voice) {
  const cst_wave* wave = utt_wave(utterance);
  if (wave == nullptr) return {};
  if (cst_wave_sample_rate(wave) != SpokenLine::kSampleRate || cst_wave_num_channels(wave) != 1)
    throw SpeechError("speech: Flite's voice " + ToString(voice) + " gave " +
                      std::to_string(cst_wave_num_channels(wave)) + " channel(s) at " +
                      std::to_string(cst_wave_sample_rate(wave)) + " Hz, not mono at 16000 Hz");
  const short* samples = cst_wave_samples(wave);
  return {samples, samples + cst_wave_num_samples(wave)};
}

}  // namespace

Voice VoiceFromName(std::string_view name) { return ParseEnum<Voice, SpeechError>(name, "speech: voice"); }

Synthesizer::Synthesizer(Voice voice) : voice_(voice) {
  const std::lock_guard lock(FliteMutex());
  flite_voice_ = RegisteredVoice(voice);
  if (flite_voice_ == nullptr) throw SpeechError("speech: Flite could not load the voice " + ToString(voice));
}

SpokenLine Synthesizer::Synthesize(std::string_view text) const {
  if (text.find('\0') != std::string_view::npos)
    throw SpeechError("speech: the line holds a NUL byte at byte " + std::to_string(text.find('\0')));
  const std::string c_text(text);
  const std::lock_guard lock(FliteMutex());
  const SeededRand seeded_rand;
  const std::unique_ptr<cst_utterance, UtteranceDeleter> utterance(
      SynthesizeOrNull(c_text.c_str(), static_cast<cst_voice*>(flite_voice_)));
  if (!utterance) throw SpeechError("speech: Flite failed on the line \"" + c_text + "\" (its message above)");
  SpokenLine line;
  line.samples = SamplesOf(utterance.get(), voice_);
  line.phones = PhonesOf(utterance.get());
  line.tokens = TokensOf(utterance.get());
  return line;
}

}  // namespace arview::speech
