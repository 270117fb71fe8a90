#include "audio/alsa_pcm.h"

#include <cerrno>
#include <cstdarg>
#include <mutex>

#include "audio/audio_error.h"
#include "audio/pcm.h"

namespace arview::audio {

namespace {

// ALSA prints its errors to stderr by default; ours carry the same news in one line.
void IgnoreAlsaMessage(const char*, int, const char*, int, const char*, ...) {}

void SilenceAlsa() {
  static std::once_flag once;
  std::call_once(once, [] { snd_lib_error_set_handler(&IgnoreAlsaMessage); });
}

std::string AlsaText(int error) { return snd_strerror(error); }

}  // namespace

std::string DeviceLabel(PcmDirection direction, const std::string& device) {
  return (direction == PcmDirection::kPlayback ? "sound output '" : "microphone '") + device + "'";
}

OpenedPcm OpenSpeechPcm(const std::string& device, PcmDirection direction, snd_pcm_uframes_t period_frames,
                        snd_pcm_uframes_t buffer_frames) {
  SilenceAlsa();
  const std::string label = DeviceLabel(direction, device);
  auto fail = [&](const std::string& what, int error) -> OpenedPcm {
    throw AudioError(label + ": " + what + " (ALSA: " + AlsaText(error) + ")");
  };
  snd_pcm_t* raw = nullptr;
  const auto stream = direction == PcmDirection::kPlayback ? SND_PCM_STREAM_PLAYBACK : SND_PCM_STREAM_CAPTURE;
  int error = snd_pcm_open(&raw, device.c_str(), stream, 0);
  if (error < 0) return fail("no such device, or it cannot be opened", error);
  OpenedPcm opened;
  opened.pcm.reset(raw);
  snd_pcm_t* pcm = raw;

  snd_pcm_hw_params_t* hw = nullptr;
  snd_pcm_hw_params_alloca(&hw);
  unsigned rate = kSpeechRate;
  if ((error = snd_pcm_hw_params_any(pcm, hw)) < 0) return fail("has no configuration", error);
  if ((error = snd_pcm_hw_params_set_rate_resample(pcm, hw, 1)) < 0 ||
      (error = snd_pcm_hw_params_set_access(pcm, hw, SND_PCM_ACCESS_RW_INTERLEAVED)) < 0 ||
      (error = snd_pcm_hw_params_set_format(pcm, hw, SND_PCM_FORMAT_S16_LE)) < 0 ||
      (error = snd_pcm_hw_params_set_channels(pcm, hw, 1)) < 0 ||
      (error = snd_pcm_hw_params_set_rate(pcm, hw, rate, 0)) < 0) {
    return fail("does not take 16000 Hz mono 16-bit audio (a 'plughw:' name converts)", error);
  }
  if ((error = snd_pcm_hw_params_set_period_size_near(pcm, hw, &period_frames, nullptr)) < 0 ||
      (error = snd_pcm_hw_params_set_buffer_size_near(pcm, hw, &buffer_frames)) < 0) {
    return fail("refuses a period of " + std::to_string(period_frames) + " frames", error);
  }
  if ((error = snd_pcm_hw_params(pcm, hw)) < 0) return fail("cannot be configured", error);
  snd_pcm_hw_params_get_period_size(hw, &opened.period_frames, nullptr);
  snd_pcm_hw_params_get_buffer_size(hw, &opened.buffer_frames);

  snd_pcm_sw_params_t* sw = nullptr;
  snd_pcm_sw_params_alloca(&sw);
  if ((error = snd_pcm_sw_params_current(pcm, sw)) < 0 ||
      (error = snd_pcm_sw_params_set_avail_min(pcm, sw, opened.period_frames)) < 0 ||
      // Playback starts with one period queued (ALSA's default waits for a full buffer, which a
      // player that keeps less queued would never reach).
      (error = snd_pcm_sw_params_set_start_threshold(
           pcm, sw, direction == PcmDirection::kPlayback ? opened.period_frames : 1)) < 0 ||
      (error = snd_pcm_sw_params(pcm, sw)) < 0) {
    return fail("refuses its start threshold", error);
  }
  if ((error = snd_pcm_prepare(pcm)) < 0) return fail("cannot be prepared", error);
  return opened;
}

std::string PcmFaultLine(PcmDirection direction, const std::string& device, int alsa_error) {
  const int code = -alsa_error;
  const bool gone = code == ENODEV || code == EBADFD || code == ENOTTY || code == EIO || code == ENXIO;
  return DeviceLabel(direction, device) + (gone ? ": the device disappeared" : ": failed") + " (ALSA: " +
         AlsaText(alsa_error) + "); " + (direction == PcmDirection::kPlayback ? "going on without sound" : "going on without listening");
}

bool IsRecoverable(int alsa_error) { return alsa_error == -EPIPE || alsa_error == -ESTRPIPE || alsa_error == -EINTR; }

}  // namespace arview::audio
