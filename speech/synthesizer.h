#pragma once
// Text to speech through Flite: 16 kHz mono 16-bit audio, each phone's start and end, and the
// start of each token Flite read (docs/speech.md). Flite keeps process-wide state that is not
// guarded (its list of voices, its error jump buffer, each voice library's one registered voice,
// the lexicon, rand()), so every call into Flite in this module holds one process-wide lock:
// any number of Synthesizers on any threads are safe, and they synthesize one line at a time
// between them.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/enum_table.h"
#include "base/error.h"

namespace arview::speech {

// Every error of this module: what() names the voice, the line or the markup position.
class SpeechError : public Error {
 public:
  using Error::Error;
};

// Flite's three 16 kHz US English voices (clustergen): a woman (slt), two men (rms, awb).
enum class Voice { kSlt, kRms, kAwb };
constexpr auto EnumNames(Voice) {
  return EnumTable<Voice, 3>{{{Voice::kSlt, "slt"}, {Voice::kRms, "rms"}, {Voice::kAwb, "awb"}}};
}

// The voice named `name`; a SpeechError naming it and the voices there are otherwise.
Voice VoiceFromName(std::string_view name);

struct Phone {
  std::string name;  // Flite's US phone set (CMU, "pau" for silence)
  double start_s = 0;
  double end_s = 0;
};

// A token of the text as Flite read it (whitespace-separated, leading and trailing punctuation
// taken off), and when its first phone starts; none when Flite says nothing for it ("--").
struct SpokenToken {
  std::string name;
  std::optional<double> start_s;
};

struct SpokenLine {
  static constexpr int kSampleRate = 16000;
  std::vector<std::int16_t> samples;  // mono, kSampleRate
  std::vector<Phone> phones;          // in time order, each starting where the last ended
  std::vector<SpokenToken> tokens;    // in text order
  double DurationSeconds() const { return static_cast<double>(samples.size()) / kSampleRate; }
};

class Synthesizer {
 public:
  explicit Synthesizer(Voice voice);

  // The line's audio and timing. Text holding a NUL byte is refused (Flite reads C strings).
  // Synthesizing the same text twice with one voice gives the same bytes and the same times.
  SpokenLine Synthesize(std::string_view text) const;

  Voice voice() const { return voice_; }

 private:
  Voice voice_;
  void* flite_voice_;  // cst_voice*, owned by Flite's voice library for the whole process
};

}  // namespace arview::speech
