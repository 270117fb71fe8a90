#include "audio/audio_out.h"

#include <algorithm>

#include "audio/audio_error.h"

namespace arview::audio {

AudioOut ParseAudioOut(std::string_view value) {
  if (value == "none") return AudioOut{false, ""};
  if (value.empty()) throw AudioError("--audio-out: empty; give default, none or an ALSA device name (hw:1,0)");
  const bool printable = std::all_of(value.begin(), value.end(), [](char c) {
    return static_cast<unsigned char>(c) > 0x20 && static_cast<unsigned char>(c) != 0x7F;
  });
  if (!printable) throw AudioError("--audio-out: '" + std::string(value) + "' is not an ALSA device name (a space or control character)");
  return AudioOut{true, std::string(value)};
}

OpenedAudioOut OpenAudioOut(const AudioOut& out, PlayerOptions options) {
  if (!out.enabled) return {};
  options.device = out.device;
  try {
    return {std::make_unique<ClipPlayer>(options), ""};
  } catch (const AudioError& error) {
    return {nullptr, std::string("no sound: ") + error.what() + "; going on silent"};
  }
}

}  // namespace arview::audio
