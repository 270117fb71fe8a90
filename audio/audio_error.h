#pragma once

#include "base/error.h"

namespace arview::audio {

// Anything in audio/ that cannot be done: a WAV file that is not 16-bit PCM or is damaged, a
// sound device that cannot be opened or configured, a clip that is not 16 kHz mono.
struct AudioError : Error {
  using Error::Error;
};

}  // namespace arview::audio
