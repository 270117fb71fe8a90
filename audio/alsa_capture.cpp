#include "audio/alsa_capture.h"

#include <thread>

#include "audio/alsa_pcm.h"
#include "audio/audio_error.h"

namespace arview::audio {

AlsaCapture::AlsaCapture(const CaptureOptions& options)
    : AudioSource("arview-mic", options.block_samples),
      device_(options.device),
      // Periods of one block, a buffer of eight: 160 ms of slack for a slow callback.
      pcm_(std::make_unique<OpenedPcm>(
          OpenSpeechPcm(options.device, PcmDirection::kCapture, options.block_samples, 8 * options.block_samples))) {}

AlsaCapture::~AlsaCapture() { StopAndJoin(); }

AudioSource::Read AlsaCapture::ReadBlock(std::span<std::int16_t> block, const std::stop_token& stop) {
  snd_pcm_t* pcm = pcm_->pcm.get();
  snd_pcm_sframes_t got = 0;
  while (true) {
    got = snd_pcm_readi(pcm, block.data(), block.size());
    if (got >= 0) break;
    const int error = static_cast<int>(got);
    if (!IsRecoverable(error) || snd_pcm_recover(pcm, error, 1) < 0) {
      throw AudioError(PcmFaultLine(PcmDirection::kCapture, device_, error));
    }
    if (error == -EPIPE) ++overruns_;
    // The samples lost in an overrun are not in the stream: the pace starts again from here.
    started_ = false;
    if (stop.stop_requested()) return {};
  }
  if (got == 0) return {};
  snd_pcm_sframes_t delay = 0;
  if (snd_pcm_delay(pcm, &delay) < 0 || delay < 0) delay = 0;
  TimePoint now = Clock::now();
  if (!started_) {
    first_heard_ = now - SpeechDuration(delay + got);
    read_ = 0;
    started_ = true;
  }
  // A device that is not paced by a sound card returns at once: wait until the block's last
  // sample would have been heard. For a real card this time has passed already.
  const TimePoint block_end = first_heard_ + SpeechDuration(read_ + got);
  if (block_end > now) {
    std::this_thread::sleep_until(block_end);
    now = block_end;
  }
  // A card's block was heard `delay + got` samples before now. A device without a delay is
  // paced by us alone: its block is heard where the pace puts it, even when this thread woke
  // late (under load it can, and the block's time must not move with it).
  device_reports_delay_ = device_reports_delay_ || delay > 0;
  const TimePoint heard_at = device_reports_delay_ ? now - SpeechDuration(delay + got) : first_heard_ + SpeechDuration(read_);
  read_ += got;
  return {static_cast<std::size_t>(got), heard_at};
}

void AlsaCapture::Finish() { pcm_.reset(); }

}  // namespace arview::audio
