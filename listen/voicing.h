#pragma once
// Whether audio holds voiced sound: a spoken command has vowels, whose glottal pulses repeat
// every 2.5 to 20 ms; noise forced onto a grammar ("yes" out of a hiss: the s is noise-like)
// has none. The recognizer's last gate on a result (docs/listen.md, "Confidence").

#include <cstdint>
#include <span>

namespace arview::listen {

// The share of the 25 ms frames (10 ms apart) of `samples` (16 kHz) whose pre-emphasized
// normalized autocorrelation peaks above 0.5 at a lag between 2.5 and 20 ms (a pitch of 50 to
// 400 Hz). Frames under 1% of full scale (RMS) count as unvoiced. 0 for fewer than one frame.
double VoicedFraction(std::span<const std::int16_t> samples);

}  // namespace arview::listen
