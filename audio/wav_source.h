#pragma once
// A WAV file as a microphone: its samples (16 kHz mono, converted or refused as the caller
// chooses, audio/wav.h) delivered in blocks on a thread of the source's own, each block once the
// pacing clock has reached the time its last sample would have been heard. `replay --audio-in`
// and the tests feed recognition with it exactly as the microphone would.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "audio/audio_source.h"
#include "audio/pacing_clock.h"
#include "audio/wav.h"

namespace arview::audio {

struct WavSourceOptions {
  std::size_t block_samples = 320;  // 20 ms at 16 kHz
  SpeechConversion conversion = SpeechConversion::kRefuse;
};

class WavFileSource final : public AudioSource {
 public:
  // Reads the whole file now (errors here, on the caller's thread). `clock` must outlive the
  // source; sample 0 is heard when Start is called, by that clock.
  WavFileSource(const std::filesystem::path& file, PacingClock& clock, const WavSourceOptions& options = {});
  // Samples already in memory (16 kHz mono), for tests and synthesized speech.
  WavFileSource(std::vector<std::int16_t> samples, PacingClock& clock, std::size_t block_samples = 320);
  ~WavFileSource() override;

 private:
  Read ReadBlock(std::span<std::int16_t> block, const std::stop_token& stop) override;

  std::vector<std::int16_t> samples_;
  PacingClock& clock_;
  std::size_t next_ = 0;
  bool started_ = false;
  TimePoint start_;
};

}  // namespace arview::audio
