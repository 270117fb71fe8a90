#include "audio/wav.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>

#include "audio/audio_error.h"

namespace arview::audio {
namespace {

PcmAudio Ramp(int rate, int channels, std::size_t frames) {
  PcmAudio audio{rate, channels, {}};
  for (std::size_t i = 0; i < frames * static_cast<std::size_t>(channels); ++i) {
    audio.samples.push_back(static_cast<std::int16_t>((static_cast<int>(i) * 37) % 65536 - 32768));
  }
  return audio;
}

std::span<const std::uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

void PutU16(std::string& bytes, std::size_t at, std::uint16_t v) {
  bytes[at] = static_cast<char>(v & 0xFF);
  bytes[at + 1] = static_cast<char>(v >> 8);
}
void PutU32(std::string& bytes, std::size_t at, std::uint32_t v) {
  PutU16(bytes, at, static_cast<std::uint16_t>(v & 0xFFFF));
  PutU16(bytes, at + 2, static_cast<std::uint16_t>(v >> 16));
}

// The message ParseWav throws for `bytes`, or "" when it parses.
std::string Refusal(const std::string& bytes) {
  try {
    ParseWav(Bytes(bytes), "talk.wav");
  } catch (const AudioError& error) {
    return error.what();
  }
  return "";
}

std::filesystem::path TempFile(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("arview-wav-test-" + std::to_string(::getpid()) + "-" + name);
}

TEST(Wav, MonoAndStereoAtAnyRateComeBackAsWritten) {
  for (const PcmAudio& audio : {Ramp(16000, 1, 1000), Ramp(44100, 2, 777), Ramp(8000, 1, 0), Ramp(384000, 2, 3)}) {
    const PcmAudio back = ParseWav(Bytes(EncodeWav(audio, "x.wav")), "x.wav");
    EXPECT_EQ(back.sample_rate, audio.sample_rate);
    EXPECT_EQ(back.channels, audio.channels);
    EXPECT_EQ(back.samples, audio.samples);
  }
}

TEST(Wav, WriteWavIsReadBackFromDisk) {
  const auto file = TempFile("round.wav");
  const PcmAudio audio = Ramp(22050, 2, 500);
  WriteWav(file, audio);
  const PcmAudio back = ReadWav(file);
  EXPECT_EQ(back.samples, audio.samples);
  EXPECT_EQ(back.sample_rate, 22050);
  std::filesystem::remove(file);
}

TEST(Wav, TheCanonicalHeaderIs44BytesWithSizesThatAddUp) {
  const std::string bytes = EncodeWav(Ramp(16000, 1, 10), "x.wav");
  ASSERT_EQ(bytes.size(), 44u + 20u);
  EXPECT_EQ(bytes.substr(0, 4), "RIFF");
  EXPECT_EQ(bytes.substr(8, 8), "WAVEfmt ");
  EXPECT_EQ(bytes.substr(36, 4), "data");
}

TEST(Wav, OtherChunksAndAnOddSizedOneWithItsPadAreSkipped) {
  std::string bytes = EncodeWav(Ramp(16000, 1, 4), "x.wav");
  // A 3-byte LIST chunk and its pad byte between fmt and data.
  bytes.insert(36, std::string("LIST\x03\x00\x00\x00" "abc\x00", 12));
  PutU32(bytes, 4, static_cast<std::uint32_t>(bytes.size() - 8));
  EXPECT_EQ(Refusal(bytes), "");
  EXPECT_EQ(ParseWav(Bytes(bytes), "x").samples.size(), 4u);
}

TEST(Wav, ExtensiblePcmIsRead) {
  std::string bytes = EncodeWav(Ramp(48000, 2, 4), "x.wav");
  std::string ext(24, '\0');
  PutU16(ext, 0, 22);     // cbSize
  PutU16(ext, 2, 16);     // valid bits
  PutU32(ext, 4, 3);      // channel mask
  PutU16(ext, 8, 1);      // PCM subformat
  std::memcpy(ext.data() + 10, "\x00\x00\x00\x00\x10\x00\x80\x00\x00\xAA\x00\x38\x9B\x71", 14);
  bytes.insert(36, ext);
  PutU32(bytes, 16, 40);
  PutU16(bytes, 20, 0xFFFE);
  PutU32(bytes, 4, static_cast<std::uint32_t>(bytes.size() - 8));
  EXPECT_EQ(Refusal(bytes), "");
}

TEST(Wav, EveryDamageIsOneLineNamingTheFileAndTheProblem) {
  const std::string good = EncodeWav(Ramp(16000, 1, 8), "x.wav");
  struct Case {
    std::string name;
    std::string bytes;
    std::string message;
  };
  std::vector<Case> cases;
  auto damaged = [&](const std::string& name, auto change, const std::string& message) {
    std::string bytes = good;
    change(bytes);
    cases.push_back({name, bytes, message});
  };
  damaged("not RIFF", [](std::string& b) { b[0] = 'X'; }, "talk.wav: is not a WAV file (no RIFF/WAVE header)");
  damaged("empty", [](std::string& b) { b.clear(); }, "talk.wav: is not a WAV file (no RIFF/WAVE header)");
  damaged("RIFF size", [](std::string& b) { PutU32(b, 4, 1000); }, "talk.wav: its RIFF header says 1008 bytes, the file has 60");
  damaged("truncated", [](std::string& b) { b.resize(50); PutU32(b, 4, 42); },
          "talk.wav: its 'data' chunk at byte 36 claims 16 bytes, past the end of the file");
  damaged("chunk header", [](std::string& b) { b += "ab"; PutU32(b, 4, static_cast<std::uint32_t>(b.size() - 8)); },
          "talk.wav: has a truncated chunk header at byte 60");
  damaged("float", [](std::string& b) { PutU16(b, 20, 3); }, "talk.wav: has format tag 3 (IEEE float); only 16-bit PCM (tag 1) is read");
  damaged("8 bits", [](std::string& b) { PutU16(b, 34, 8); }, "talk.wav: has 8 bits per sample; only 16-bit PCM is read");
  damaged("channels", [](std::string& b) { PutU16(b, 22, 6); }, "talk.wav: has 6 channels; only mono and stereo are read");
  damaged("no channels", [](std::string& b) { PutU16(b, 22, 0); }, "talk.wav: has 0 channels; only mono and stereo are read");
  damaged("rate", [](std::string& b) { PutU32(b, 24, 0); }, "talk.wav: has a sample rate of 0 Hz, outside 1000 to 384000");
  damaged("huge rate", [](std::string& b) { PutU32(b, 24, 4000000000u); },
          "talk.wav: has a sample rate of 4000000000 Hz, outside 1000 to 384000");
  damaged("block align", [](std::string& b) { PutU16(b, 32, 4); },
          "talk.wav: has a block align of 4 bytes; 1 channel(s) of 16 bits make 2");
  damaged("byte rate", [](std::string& b) { PutU32(b, 28, 16000); },
          "talk.wav: has a byte rate of 16000; 16000 Hz x 2 bytes make 32000");
  damaged("short fmt", [](std::string& b) { PutU32(b, 16, 14); }, "talk.wav: its fmt chunk has 14 bytes, fewer than 16");
  damaged("no data", [](std::string& b) { std::memcpy(b.data() + 36, "junk", 4); }, "talk.wav: has no data chunk");
  damaged("no fmt", [](std::string& b) { std::memcpy(b.data() + 12, "junk", 4); }, "talk.wav: has its data chunk before its fmt chunk");
  damaged("odd data", [](std::string& b) { b += '\x01'; PutU32(b, 40, 17); PutU32(b, 4, static_cast<std::uint32_t>(b.size() - 8)); },
          "talk.wav: its data chunk of 17 bytes is not whole frames of 2 bytes");
  damaged("two data", [](std::string& b) { b += b.substr(36); PutU32(b, 4, static_cast<std::uint32_t>(b.size() - 8)); },
          "talk.wav: has two data chunks");
  damaged("two fmt", [](std::string& b) { b.insert(36, b.substr(12, 24)); PutU32(b, 4, static_cast<std::uint32_t>(b.size() - 8)); },
          "talk.wav: has two fmt chunks");
  damaged("control id", [](std::string& b) { b += std::string("\x01\x02zz\x00\x00\x00\x01", 8); PutU32(b, 4, static_cast<std::uint32_t>(b.size() - 8)); },
          "talk.wav: its '\\x01\\x02zz' chunk at byte 60 claims 16777216 bytes, past the end of the file");
  for (const Case& c : cases) EXPECT_EQ(Refusal(c.bytes), c.message) << c.name;
}

TEST(Wav, AMissingFileIsNamed) {
  try {
    ReadWav("/nonexistent/talk.wav");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()), "/nonexistent/talk.wav: does not exist");
  }
}

TEST(Wav, SpeechIsRefusedOrResampledAsAsked) {
  const auto file = TempFile("stereo44.wav");
  WriteWav(file, Ramp(44100, 2, 4410));
  try {
    ReadSpeechWav(file, SpeechConversion::kRefuse);
    FAIL() << "no error";
  } catch (const AudioError& error) {
    EXPECT_EQ(std::string(error.what()), file.string() + ": is 44100 Hz stereo; speech must be 16000 Hz mono");
  }
  EXPECT_EQ(ReadSpeechWav(file, SpeechConversion::kResample).size(), 1600u);
  const auto speech = TempFile("speech.wav");
  WriteWav(speech, Ramp(16000, 1, 123));
  EXPECT_EQ(ReadSpeechWav(speech, SpeechConversion::kRefuse), Ramp(16000, 1, 123).samples);
  std::filesystem::remove(file);
  std::filesystem::remove(speech);
}

TEST(Wav, WritingWhatCannotBeReadIsRefused) {
  EXPECT_THROW(EncodeWav(PcmAudio{16000, 3, {1, 2, 3}}, "x.wav"), AudioError);
  EXPECT_THROW(EncodeWav(PcmAudio{500, 1, {1}}, "x.wav"), AudioError);
  EXPECT_THROW(EncodeWav(PcmAudio{16000, 2, {1, 2, 3}}, "x.wav"), AudioError);
}

}  // namespace
}  // namespace arview::audio
