#pragma once
// `--audio-out default|none|<device>`: what the flag means, and opening the player it asks for.
// No sound device is not an error: the caller is told so in one line and goes on silent.

#include <memory>
#include <string>
#include <string_view>

#include "audio/clip_player.h"

namespace arview::audio {

struct AudioOut {
  bool enabled = true;              // false: --audio-out none
  std::string device = "default";   // an ALSA PCM name: default, hw:1,0, plughw:CARD=USB, a .asoundrc's
};

// "none" → off; anything else names an ALSA device. An empty value or one with a control
// character or space is an AudioError naming the flag.
AudioOut ParseAudioOut(std::string_view value);

struct OpenedAudioOut {
  std::unique_ptr<ClipPlayer> player;  // null: silent
  std::string note;                    // why silent, one line for the user; empty when playing or off
};

// The player for `out` with `options`' timing (its device replaced by out.device), or none with
// the note "no sound: sound output 'X': ... (ALSA: ...); going on silent" when it cannot be opened.
OpenedAudioOut OpenAudioOut(const AudioOut& out, PlayerOptions options = {});

}  // namespace arview::audio
