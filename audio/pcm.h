#pragma once
// The one sample format the appliance speaks and listens in, and a buffer of any other that a
// WAV file may hold.

#include <chrono>
#include <cstdint>
#include <vector>

namespace arview::audio {

// Speech in and out: 16 kHz mono int16 (Flite's voices, PocketSphinx's en-us model).
inline constexpr int kSpeechRate = 16000;

// The time of a sample on the session's steady clock: a clip's first sample is due then, a
// captured block's first sample was heard then.
using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;

// How long `samples` of speech last, in the clock's ticks (from the count, so no error builds up).
inline Clock::duration SpeechDuration(std::int64_t samples) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(static_cast<double>(samples) / kSpeechRate));
}

// 16-bit PCM at any rate, one or two channels, interleaved (left, right, left, ...).
struct PcmAudio {
  int sample_rate = kSpeechRate;
  int channels = 1;
  std::vector<std::int16_t> samples;

  std::size_t frames() const { return channels > 0 ? samples.size() / static_cast<std::size_t>(channels) : 0; }
  double seconds() const { return sample_rate > 0 ? static_cast<double>(frames()) / sample_rate : 0.0; }
};

}  // namespace arview::audio
