#pragma once
// The microphone through ALSA capture (`--mic default` or a named device), delivered as 16 kHz
// mono blocks on the thread `arview-mic` (audio/audio_source.h). A block's heard_at is the
// steady clock's time at its first sample, from snd_pcm_delay. A device that delivers faster
// than real time (ALSA's `null` or `file` plugins, the tests' emulated microphone) is paced to
// real time, as a sound card would be. An overrun (the callback too slow) is counted and
// capture goes on; a device that fails or disappears ends the source with one line
// (SourceEnd::error), never a crash.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "audio/audio_source.h"

namespace arview::audio {

struct OpenedPcm;  // audio/alsa_pcm.h: ALSA's headers stay out of the users' translation units

struct CaptureOptions {
  std::string device = "default";
  std::size_t block_samples = 320;  // 20 ms at 16 kHz
};

class AlsaCapture final : public AudioSource {
 public:
  // Opens the device now (an AudioError naming it when it cannot); capture starts with Start.
  explicit AlsaCapture(const CaptureOptions& options);
  ~AlsaCapture() override;

  // Overruns so far: ALSA dropped input because a block was not read in time. Any thread.
  std::int64_t overruns() const { return overruns_.load(); }

 private:
  Read ReadBlock(std::span<std::int16_t> block, const std::stop_token& stop) override;
  void Finish() override;

  const std::string device_;
  std::unique_ptr<OpenedPcm> pcm_;
  std::atomic<std::int64_t> overruns_{0};
  // The pacing: when sample 0 was heard, and how many samples were read since.
  bool started_ = false;
  TimePoint first_heard_;
  std::int64_t read_ = 0;
  // A sound card reports the samples captured and not yet read; ALSA's `file` and `null`
  // devices (the tests' microphone) never do, and their blocks are placed by our own pace.
  bool device_reports_delay_ = false;
};

}  // namespace arview::audio
