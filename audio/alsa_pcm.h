#pragma once
// An ALSA PCM opened for speech (16 kHz, mono, signed 16-bit, interleaved read/write), shared
// by the player and the microphone. ALSA's own error printing is turned off: every failure is
// an AudioError whose line names the device and what ALSA said.

#include <alsa/asoundlib.h>

#include <memory>
#include <string>

namespace arview::audio {

struct PcmCloser {
  void operator()(snd_pcm_t* pcm) const { snd_pcm_close(pcm); }
};
using PcmHandle = std::unique_ptr<snd_pcm_t, PcmCloser>;

struct OpenedPcm {
  PcmHandle pcm;
  snd_pcm_uframes_t period_frames = 0;  // what ALSA granted
  snd_pcm_uframes_t buffer_frames = 0;
};

enum class PcmDirection { kPlayback, kCapture };

// "sound output 'default'" / "microphone 'hw:1'": how error lines name a device.
std::string DeviceLabel(PcmDirection direction, const std::string& device);

// Opens `device` at 16 kHz mono S16 (ALSA's plug layers convert where the device's own format
// differs), asking for periods of `period_frames` and a buffer of `buffer_frames`. Playback
// starts once one period is queued. Throws AudioError naming the device.
OpenedPcm OpenSpeechPcm(const std::string& device, PcmDirection direction, snd_pcm_uframes_t period_frames,
                        snd_pcm_uframes_t buffer_frames);

// The line for an ALSA read/write/delay error that cannot be recovered from: a device that went
// away (ENODEV, EBADFD, ENOTTY, EIO: a USB card unplugged) is said so.
std::string PcmFaultLine(PcmDirection direction, const std::string& device, int alsa_error);

// True for the errors snd_pcm_recover handles (an underrun or overrun, a suspend, EINTR).
bool IsRecoverable(int alsa_error);

}  // namespace arview::audio
