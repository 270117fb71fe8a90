#include "audio/wav_source.h"

#include <algorithm>
#include <cstring>

namespace arview::audio {

WavFileSource::WavFileSource(const std::filesystem::path& file, PacingClock& clock, const WavSourceOptions& options)
    : AudioSource("arview-wavin", options.block_samples),
      samples_(ReadSpeechWav(file, options.conversion)),
      clock_(clock) {}

WavFileSource::WavFileSource(std::vector<std::int16_t> samples, PacingClock& clock, std::size_t block_samples)
    : AudioSource("arview-wavin", block_samples), samples_(std::move(samples)), clock_(clock) {}

WavFileSource::~WavFileSource() { StopAndJoin(); }

AudioSource::Read WavFileSource::ReadBlock(std::span<std::int16_t> block, const std::stop_token& stop) {
  if (!started_) {
    start_ = clock_.Now();
    started_ = true;
  }
  const std::size_t count = std::min(block.size(), samples_.size() - next_);
  if (count == 0) return {};
  // Offsets from the start, not a running sum: the pace does not drift with rounding.
  const TimePoint heard_at = start_ + SpeechDuration(static_cast<std::int64_t>(next_));
  if (!clock_.SleepUntil(start_ + SpeechDuration(static_cast<std::int64_t>(next_ + count)), stop)) return {};
  std::memcpy(block.data(), samples_.data() + next_, count * sizeof(std::int16_t));
  next_ += count;
  return {count, heard_at};
}

}  // namespace arview::audio
