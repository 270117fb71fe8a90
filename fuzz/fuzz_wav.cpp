// The WAV reader (audio/wav.h), for `replay --audio-in` and the recognizer's tests: the RIFF
// size, the chunk walk, fmt and data. What it accepts must hold together: 1 or 2 channels, a rate
// in range, whole frames; written back by EncodeWav it parses to the same audio; converted to
// speech (when small enough to stay fast) it has the length the ratio gives.
// Seeds (written by LLVMFuzzerInitialize): a 16 kHz mono WAV, a 44.1 kHz stereo one with a LIST
// chunk of odd size, and a WAVE_FORMAT_EXTENSIBLE one.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>

#include "audio/audio_error.h"
#include "audio/resample.h"
#include "audio/wav.h"
#include "fuzz/fuzz_support.h"

namespace {

using arview::audio::PcmAudio;

std::string Seed(int rate, int channels, std::size_t frames) {
  PcmAudio audio{rate, channels, {}};
  for (std::size_t i = 0; i < frames * static_cast<std::size_t>(channels); ++i) {
    audio.samples.push_back(static_cast<std::int16_t>(i * 977));
  }
  return arview::audio::EncodeWav(audio, "seed");
}

void SetU32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  arview::fuzz::WriteBytes(seeds / "mono16k.wav", Seed(16000, 1, 64));
  std::string list = Seed(44100, 2, 32);
  list.insert(36, std::string("LIST\x05\x00\x00\x00" "INFOx\x00", 14));
  SetU32(list, 4, static_cast<std::uint32_t>(list.size() - 8));
  arview::fuzz::WriteBytes(seeds / "stereo44k-list.wav", list);
  std::string extensible = Seed(48000, 1, 16);
  std::string ext(24, '\0');
  ext[0] = 22;   // cbSize
  ext[2] = 16;   // valid bits
  ext[4] = 4;    // channel mask: front centre
  ext[8] = 1;    // the PCM subformat
  std::memcpy(ext.data() + 10, "\x00\x00\x00\x00\x10\x00\x80\x00\x00\xAA\x00\x38\x9B\x71", 14);
  extensible.insert(36, ext);
  SetU32(extensible, 16, 40);
  extensible[20] = '\xFE';
  extensible[21] = '\xFF';
  SetU32(extensible, 4, static_cast<std::uint32_t>(extensible.size() - 8));
  arview::fuzz::WriteBytes(seeds / "extensible48k.wav", extensible);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const PcmAudio audio = arview::audio::ParseWav(std::span(data, size), "fuzz.wav");
    if (audio.channels != 1 && audio.channels != 2) std::abort();
    if (audio.sample_rate < arview::audio::kMinWavRate || audio.sample_rate > arview::audio::kMaxWavRate) std::abort();
    if (audio.samples.size() % static_cast<std::size_t>(audio.channels) != 0) std::abort();
    const std::string again = arview::audio::EncodeWav(audio, "fuzz.wav");
    const PcmAudio back = arview::audio::ParseWav(
        std::span(reinterpret_cast<const std::uint8_t*>(again.data()), again.size()), "again.wav");
    if (back.samples != audio.samples || back.sample_rate != audio.sample_rate || back.channels != audio.channels) std::abort();
    const std::uint64_t out_samples = std::uint64_t{audio.frames()} * arview::audio::kSpeechRate / static_cast<std::uint64_t>(audio.sample_rate);
    if (out_samples <= 16000) {
      if (arview::audio::ToSpeechFormat(audio).size() != out_samples) std::abort();
    }
  } catch (const arview::audio::AudioError&) {
  }
  return 0;
}
