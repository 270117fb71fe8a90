#pragma once
// Whether audio sounds like a voice: a spoken command has vowels, whose glottal pulses repeat
// every 2.5 to 20 ms at a pitch that keeps moving; noise forced onto a grammar ("yes" out of a
// hiss) has no pitch, and music holds each note's pitch still. The recognizer's last gates on a
// result (docs/listen.md, "Confidence").

#include <cstdint>
#include <span>

namespace arview::listen {

struct Voicing {
  // The share of the 25 ms frames (10 ms apart) whose pre-emphasized normalized
  // autocorrelation peaks above 0.5 at a lag between 2.5 and 20 ms (a pitch of 50 to 400 Hz).
  // Frames under 1% of full scale (RMS) count as unvoiced.
  double voiced_fraction = 0;
  // The longest run of voiced frames, one after the other, whose peak lag is the same to the
  // sample, in seconds: a held note's period does not move; a voice's drifts within tens of ms.
  double longest_steady_pitch_s = 0;
};

// 16 kHz samples; all zero for less than one frame.
Voicing MeasureVoicing(std::span<const std::int16_t> samples);

}  // namespace arview::listen
