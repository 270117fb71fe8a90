#pragma once
// Sample-rate conversion for speech: a windowed-sinc low-pass interpolator at any ratio.
//
// The filter: h(t) = fc·sinc(fc·t)·w(t), t in input samples, with the cutoff fc = 0.9 of the
// lower of the two Nyquist frequencies (as a fraction of the input's), and w a Kaiser window
// (β = 8.6, about 85 dB of stopband rejection) spanning 16 zero crossings of the sinc on each side.
// Each output sample is the filter centred on its exact position in the input (no intermediate
// rate), the kernel tabulated at 512 points per zero crossing and interpolated linearly. The
// passband and stopband are measured in resample_test.cpp and given in docs/audio.md.

#include <cstdint>
#include <span>
#include <vector>

#include "audio/pcm.h"

namespace arview::audio {

// `samples` (mono) from `from_rate` to `to_rate`; both in [kMinWavRate, kMaxWavRate] (else an
// AudioError). The output has floor(n · to_rate / from_rate) samples; values saturate at int16.
std::vector<std::int16_t> Resample(std::span<const std::int16_t> samples, int from_rate, int to_rate);

// One channel: a stereo frame's two samples averaged (rounded toward zero), mono as it is.
std::vector<std::int16_t> DownmixToMono(const PcmAudio& audio);

// `audio` as speech wants it: 16 kHz mono.
std::vector<std::int16_t> ToSpeechFormat(const PcmAudio& audio);

}  // namespace arview::audio
