#pragma once
// WAV files: 16-bit PCM (format tag 1, or WAVE_FORMAT_EXTENSIBLE with the PCM subformat), mono
// or stereo, any rate from 1 kHz to 384 kHz. Everything is checked before a sample is trusted:
// the RIFF size against the file's, every chunk inside it, exactly one `fmt ` before one `data`,
// the format tag, channels, bits, block align and byte rate against each other, a data size of
// whole frames. A file that fails any check is an AudioError whose line names the file and the
// problem; other chunks (LIST, fact, cue, ...) are skipped.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "audio/pcm.h"

namespace arview::audio {

// The largest WAV read: 1 GiB (9 hours of 16 kHz stereo); a larger one is refused before it is read.
inline constexpr std::uintmax_t kMaxWavBytes = std::uintmax_t{1} << 30;
inline constexpr int kMinWavRate = 1000;
inline constexpr int kMaxWavRate = 384000;

// Parses a WAV file's bytes; `name` is the file the error lines name.
PcmAudio ParseWav(std::span<const std::uint8_t> bytes, const std::string& name);
// Reads and parses `file`; a missing, unreadable or oversized file is base/input_guard.h's
// InputError, which names it as well.
PcmAudio ReadWav(const std::filesystem::path& file);

// What to do with a WAV that is not 16 kHz mono, where speech must be.
enum class SpeechConversion {
  kRefuse,    // an AudioError naming the file, its rate and channels
  kResample,  // downmix to mono (the channels' mean), resample to 16 kHz (audio/resample.h)
};
// `file` as 16 kHz mono samples: as it is when it already is, else converted or refused.
std::vector<std::int16_t> ReadSpeechWav(const std::filesystem::path& file, SpeechConversion conversion);

// The bytes of a canonical 44-byte-header WAV of `audio` (format tag 1). Throws AudioError
// naming `name` when the rate or channels are outside what ParseWav accepts, or the samples are
// not whole frames or too many for a RIFF size.
std::string EncodeWav(const PcmAudio& audio, const std::string& name);
// Writes `audio` to `file` atomically (base/atomic_file.h): complete, or not at all.
void WriteWav(const std::filesystem::path& file, const PcmAudio& audio);

}  // namespace arview::audio
