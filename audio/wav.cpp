#include "audio/wav.h"

#include <array>
#include <cstring>
#include <limits>
#include <optional>

#include "audio/audio_error.h"
#include "audio/resample.h"
#include "base/atomic_file.h"
#include "base/input_guard.h"

namespace arview::audio {

namespace {

constexpr std::uint16_t kFormatPcm = 1;
constexpr std::uint16_t kFormatExtensible = 0xFFFE;
// KSDATAFORMAT_SUBTYPE_PCM after its first two bytes (the format tag, 1).
constexpr std::array<std::uint8_t, 14> kPcmSubformatTail = {0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x80,
                                                            0x00, 0x00, 0xAA, 0x00, 0x38, 0x9B, 0x71};

std::uint16_t U16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
std::uint32_t U32(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
bool IdIs(std::span<const std::uint8_t> b, std::size_t at, const char* id) { return std::memcmp(&b[at], id, 4) == 0; }

// A chunk id as text for an error line; bytes outside printable ASCII as \xNN.
std::string PrintableId(std::span<const std::uint8_t> b, std::size_t at) {
  static const char* const kHex = "0123456789abcdef";
  std::string id;
  for (std::size_t i = at; i < at + 4; ++i) {
    if (b[i] >= 0x20 && b[i] < 0x7F) {
      id += static_cast<char>(b[i]);
    } else {
      id += std::string("\\x") + kHex[b[i] >> 4] + kHex[b[i] & 15];
    }
  }
  return id;
}

struct Format {
  int channels = 0;
  int sample_rate = 0;
};

// The `fmt ` chunk's body, every field checked against the others.
Format ParseFormat(std::span<const std::uint8_t> body, const std::string& name) {
  auto fail = [&](const std::string& what) -> Format { throw AudioError(name + ": " + what); };
  if (body.size() < 16) return fail("its fmt chunk has " + std::to_string(body.size()) + " bytes, fewer than 16");
  const std::uint16_t tag = U16(body, 0);
  const int channels = U16(body, 2);
  const std::uint32_t rate = U32(body, 4);
  const std::uint32_t byte_rate = U32(body, 8);
  const int block_align = U16(body, 12);
  const int bits = U16(body, 14);
  if (tag == kFormatExtensible) {
    if (body.size() < 40 || U16(body, 16) < 22) return fail("its WAVE_FORMAT_EXTENSIBLE fmt chunk is shorter than 40 bytes");
    if (U16(body, 24) != kFormatPcm || std::memcmp(&body[26], kPcmSubformatTail.data(), kPcmSubformatTail.size()) != 0) {
      return fail("is WAVE_FORMAT_EXTENSIBLE with a subformat other than PCM; only 16-bit PCM is read");
    }
    if (U16(body, 18) != 16) return fail("has " + std::to_string(U16(body, 18)) + " valid bits per sample, not 16");
  } else if (tag != kFormatPcm) {
    const std::string known = tag == 3 ? " (IEEE float)" : tag == 6 ? " (A-law)" : tag == 7 ? " (mu-law)" : "";
    return fail("has format tag " + std::to_string(tag) + known + "; only 16-bit PCM (tag 1) is read");
  }
  if (bits != 16) return fail("has " + std::to_string(bits) + " bits per sample; only 16-bit PCM is read");
  if (channels != 1 && channels != 2) return fail("has " + std::to_string(channels) + " channels; only mono and stereo are read");
  if (rate < static_cast<std::uint32_t>(kMinWavRate) || rate > static_cast<std::uint32_t>(kMaxWavRate)) {
    return fail("has a sample rate of " + std::to_string(rate) + " Hz, outside " + std::to_string(kMinWavRate) + " to " +
                std::to_string(kMaxWavRate));
  }
  if (block_align != channels * 2) {
    return fail("has a block align of " + std::to_string(block_align) + " bytes; " + std::to_string(channels) +
                " channel(s) of 16 bits make " + std::to_string(channels * 2));
  }
  if (byte_rate != rate * static_cast<std::uint32_t>(block_align)) {
    return fail("has a byte rate of " + std::to_string(byte_rate) + "; " + std::to_string(rate) + " Hz x " +
                std::to_string(block_align) + " bytes make " + std::to_string(rate * static_cast<std::uint32_t>(block_align)));
  }
  return Format{channels, static_cast<int>(rate)};
}

}  // namespace

PcmAudio ParseWav(std::span<const std::uint8_t> bytes, const std::string& name) {
  auto fail = [&](const std::string& what) -> PcmAudio { throw AudioError(name + ": " + what); };
  if (bytes.size() < 12 || !IdIs(bytes, 0, "RIFF") || !IdIs(bytes, 8, "WAVE")) {
    return fail("is not a WAV file (no RIFF/WAVE header)");
  }
  if (bytes.size() > kMaxWavBytes) return fail("is larger than the 1 GiB a WAV may be");
  const std::uint64_t riff_end = std::uint64_t{U32(bytes, 4)} + 8;
  if (riff_end != bytes.size()) {
    return fail("its RIFF header says " + std::to_string(riff_end) + " bytes, the file has " + std::to_string(bytes.size()));
  }
  std::optional<Format> format;
  std::optional<std::span<const std::uint8_t>> data;
  std::size_t at = 12;
  while (at < bytes.size()) {
    if (bytes.size() - at < 8) return fail("has a truncated chunk header at byte " + std::to_string(at));
    const std::string id = PrintableId(bytes, at);
    const std::uint64_t size = U32(bytes, at + 4);
    const std::size_t body = at + 8;
    if (size > bytes.size() - body) {
      return fail("its '" + id + "' chunk at byte " + std::to_string(at) + " claims " + std::to_string(size) +
                  " bytes, past the end of the file");
    }
    const auto contents = bytes.subspan(body, static_cast<std::size_t>(size));
    if (IdIs(bytes, at, "fmt ")) {
      if (format) return fail("has two fmt chunks");
      if (data) return fail("has its data chunk before its fmt chunk");
      format = ParseFormat(contents, name);
    } else if (IdIs(bytes, at, "data")) {
      if (!format) return fail("has its data chunk before its fmt chunk");
      if (data) return fail("has two data chunks");
      data = contents;
    }
    // Chunks are padded to an even size; the pad byte of the last one may be missing only if the
    // RIFF size says so, which the bound above already checked.
    at = body + static_cast<std::size_t>(size) + (size % 2);
  }
  if (!format) return fail("has no fmt chunk");
  if (!data) return fail("has no data chunk");
  const std::size_t frame_bytes = static_cast<std::size_t>(format->channels) * 2;
  if (data->size() % frame_bytes != 0) {
    return fail("its data chunk of " + std::to_string(data->size()) + " bytes is not whole frames of " +
                std::to_string(frame_bytes) + " bytes");
  }
  PcmAudio audio;
  audio.sample_rate = format->sample_rate;
  audio.channels = format->channels;
  audio.samples.resize(data->size() / 2);
  for (std::size_t i = 0; i < audio.samples.size(); ++i) audio.samples[i] = static_cast<std::int16_t>(U16(*data, 2 * i));
  return audio;
}

PcmAudio ReadWav(const std::filesystem::path& file) {
  const std::string bytes = ReadFileUpTo(file, kMaxWavBytes);
  return ParseWav(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), file.string());
}

std::vector<std::int16_t> ReadSpeechWav(const std::filesystem::path& file, SpeechConversion conversion) {
  PcmAudio audio = ReadWav(file);
  if (audio.sample_rate == kSpeechRate && audio.channels == 1) return std::move(audio.samples);
  if (conversion == SpeechConversion::kRefuse) {
    throw AudioError(file.string() + ": is " + std::to_string(audio.sample_rate) + " Hz " +
                     (audio.channels == 1 ? "mono" : "stereo") + "; speech must be 16000 Hz mono");
  }
  return ToSpeechFormat(audio);
}

std::string EncodeWav(const PcmAudio& audio, const std::string& name) {
  if (audio.channels != 1 && audio.channels != 2) {
    throw AudioError(name + ": cannot write " + std::to_string(audio.channels) + " channels; only mono and stereo");
  }
  if (audio.sample_rate < kMinWavRate || audio.sample_rate > kMaxWavRate) {
    throw AudioError(name + ": cannot write a sample rate of " + std::to_string(audio.sample_rate) + " Hz");
  }
  if (audio.samples.size() % static_cast<std::size_t>(audio.channels) != 0) {
    throw AudioError(name + ": the samples are not whole frames of " + std::to_string(audio.channels) + " channels");
  }
  const std::uint64_t data_bytes = std::uint64_t{audio.samples.size()} * 2;
  if (data_bytes + 44 > kMaxWavBytes) throw AudioError(name + ": the audio is larger than the 1 GiB a WAV may be");
  std::string out;
  out.reserve(static_cast<std::size_t>(44 + data_bytes));
  auto id = [&](const char* text) { out.append(text, 4); };
  auto u16 = [&](std::uint32_t v) { out += static_cast<char>(v & 0xFF); out += static_cast<char>((v >> 8) & 0xFF); };
  auto u32 = [&](std::uint64_t v) { u16(static_cast<std::uint32_t>(v & 0xFFFF)); u16(static_cast<std::uint32_t>(v >> 16)); };
  const auto block_align = static_cast<std::uint32_t>(audio.channels * 2);
  id("RIFF");
  u32(36 + data_bytes);
  id("WAVE");
  id("fmt ");
  u32(16);
  u16(kFormatPcm);
  u16(static_cast<std::uint32_t>(audio.channels));
  u32(static_cast<std::uint32_t>(audio.sample_rate));
  u32(static_cast<std::uint32_t>(audio.sample_rate) * block_align);
  u16(block_align);
  u16(16);
  id("data");
  u32(data_bytes);
  for (const std::int16_t s : audio.samples) u16(static_cast<std::uint16_t>(s));
  return out;
}

void WriteWav(const std::filesystem::path& file, const PcmAudio& audio) {
  WriteFileAtomically(file, EncodeWav(audio, file.string()));
}

}  // namespace arview::audio
