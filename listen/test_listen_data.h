#pragma once
// What listen/'s tests and benchmark hear: Debian's pocketsphinx-testdata recordings (read with
// a loader for exactly their two forms, headerless 16 kHz int16 and 16 kHz mono PCM WAV; the
// project's WAV reader belongs to audio/), their transcripts, word accuracy, and generated
// silence, white and pink noise and a tone mix ("music").

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace arview::listen::testing {

inline const std::filesystem::path kTestdata = "/usr/share/pocketsphinx/test/data";
inline const std::filesystem::path kModelMdef = "/usr/share/pocketsphinx/model/en-us/en-us/mdef";
inline constexpr const char* kTestdataPackage = "Debian package pocketsphinx-testdata";
inline constexpr const char* kModelPackage = "Debian package pocketsphinx-en-us";

inline std::vector<char> FileBytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot read " + path.string());
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

inline std::vector<std::int16_t> SamplesOf(const char* bytes, std::size_t size) {
  std::vector<std::int16_t> samples(size / 2);
  std::memcpy(samples.data(), bytes, samples.size() * 2);  // little-endian, as the machine
  return samples;
}

inline std::vector<std::int16_t> LoadRaw(const std::filesystem::path& path) {
  const std::vector<char> bytes = FileBytes(path);
  return SamplesOf(bytes.data(), bytes.size());
}

inline std::uint32_t Le32(const char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// The testdata's WAVs: RIFF, a 16-byte PCM fmt chunk (mono, 16 kHz, 16 bits), then data.
inline std::vector<std::int16_t> LoadTestWav(const std::filesystem::path& path) {
  const std::vector<char> bytes = FileBytes(path);
  const bool plain = bytes.size() >= 44 && std::memcmp(bytes.data(), "RIFF", 4) == 0 &&
                     std::memcmp(bytes.data() + 8, "WAVEfmt ", 8) == 0 && Le32(bytes.data() + 16) == 16 &&
                     bytes[20] == 1 && bytes[22] == 1 && Le32(bytes.data() + 24) == 16000 && bytes[34] == 16 &&
                     std::memcmp(bytes.data() + 36, "data", 4) == 0;
  if (!plain) throw std::runtime_error(path.string() + " is not the 16 kHz mono PCM WAV the test expects");
  const std::size_t size = std::min<std::size_t>(Le32(bytes.data() + 40), bytes.size() - 44);
  return SamplesOf(bytes.data() + 44, size);
}

inline std::vector<std::string> Words(const std::string& text) {
  std::istringstream in(text);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

// A Sphinx transcription file: "<s> words </s> (id)" per line → id → words.
inline std::map<std::string, std::string> ReadTranscription(const std::filesystem::path& path) {
  std::map<std::string, std::string> transcripts;
  std::ifstream file(path);
  for (std::string line; std::getline(file, line);) {
    const auto open = line.rfind('(');
    const auto close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::string words;
    for (const std::string& word : Words(line.substr(0, open))) {
      if (word == "<s>" || word == "</s>") continue;
      words += (words.empty() ? "" : " ") + word;
    }
    transcripts[line.substr(open + 1, close - open - 1)] = words;
  }
  return transcripts;
}

// Substitutions + deletions + insertions between the reference and the hypothesis (Levenshtein
// over words); word accuracy is 1 − errors / reference words, as Sphinx's word_align.pl counts.
inline std::size_t WordErrors(const std::vector<std::string>& reference, const std::vector<std::string>& hypothesis) {
  std::vector<std::size_t> row(hypothesis.size() + 1);
  for (std::size_t j = 0; j < row.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= reference.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= hypothesis.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (reference[i - 1] == hypothesis[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row.back();
}

inline std::int16_t Clip(double value) {
  return static_cast<std::int16_t>(std::clamp(std::lround(value), -32768L, 32767L));
}

inline std::vector<std::int16_t> Silence(std::size_t count) { return std::vector<std::int16_t>(count, 0); }

inline std::vector<std::int16_t> WhiteNoise(std::size_t count, double rms, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0, rms);
  std::vector<std::int16_t> samples(count);
  for (auto& s : samples) s = Clip(normal(random));
  return samples;
}

// Paul Kellett's economy pink filter over white noise (−3 dB per octave within 0.5 dB from
// 9 Hz to Nyquist), scaled to `rms`.
inline std::vector<std::int16_t> PinkNoise(std::size_t count, double rms, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0, 1);
  std::vector<double> pink(count);
  double b0 = 0, b1 = 0, b2 = 0;
  double power = 0;
  for (auto& p : pink) {
    const double white = normal(random);
    b0 = 0.99765 * b0 + white * 0.0990460;
    b1 = 0.96300 * b1 + white * 0.2965164;
    b2 = 0.57000 * b2 + white * 1.0526913;
    p = b0 + b1 + b2 + white * 0.1848;
    power += p * p;
  }
  const double scale = count ? rms / std::sqrt(power / count) : 0;
  std::vector<std::int16_t> samples(count);
  for (std::size_t i = 0; i < count; ++i) samples[i] = Clip(pink[i] * scale);
  return samples;
}

// "Music": chords of three notes with their first four harmonics, a new chord every 0.25 to
// 1 s, each note with a 10 ms attack and an exponential decay, and a bass line; peak near `peak`.
inline std::vector<std::int16_t> ToneMix(std::size_t count, double peak, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> semitone(-12, 12);
  std::uniform_real_distribution<double> length(0.25, 1.0);
  std::vector<double> mix(count, 0.0);
  std::size_t start = 0;
  while (start < count) {
    const auto span = static_cast<std::size_t>(length(random) * 16000);
    const int root = semitone(random);
    for (const int interval : {0, 4, 7, -12}) {
      const double frequency = 440.0 * std::pow(2.0, (root + interval) / 12.0);
      for (std::size_t i = start; i < std::min(count, start + span); ++i) {
        const double t = static_cast<double>(i - start) / 16000;
        const double envelope = std::min(1.0, t / 0.01) * std::exp(-3.0 * t);
        double wave = 0;
        for (int h = 1; h <= 4; ++h) wave += std::sin(2 * M_PI * frequency * h * t) / h;
        mix[i] += envelope * wave;
      }
    }
    start += span;
  }
  double highest = 1e-9;
  for (const double m : mix) highest = std::max(highest, std::abs(m));
  std::vector<std::int16_t> samples(count);
  for (std::size_t i = 0; i < count; ++i) samples[i] = Clip(mix[i] * peak / highest);
  return samples;
}

// The generated inputs that must not become commands, each `count` samples from a seed: digital
// silence, a dithered floor, white and pink noise from a quiet room to a loud fan, and the tone
// mix from background music to loud (peaks at 3% to 76% of full scale). docs/listen.md.
struct NoiseKind {
  std::string name;
  std::function<std::vector<std::int16_t>(std::uint32_t seed)> make;
};

inline std::vector<NoiseKind> NoiseKinds(std::size_t count) {
  return {
      {"silence", [count](std::uint32_t) { return Silence(count); }},
      {"dither", [count](std::uint32_t s) { return WhiteNoise(count, 3, s); }},
      {"white-30", [count](std::uint32_t s) { return WhiteNoise(count, 30, s); }},
      {"white-300", [count](std::uint32_t s) { return WhiteNoise(count, 300, s); }},
      {"white-3000", [count](std::uint32_t s) { return WhiteNoise(count, 3000, s); }},
      {"pink-30", [count](std::uint32_t s) { return PinkNoise(count, 30, s); }},
      {"pink-300", [count](std::uint32_t s) { return PinkNoise(count, 300, s); }},
      {"pink-3000", [count](std::uint32_t s) { return PinkNoise(count, 3000, s); }},
      {"music-1000", [count](std::uint32_t s) { return ToneMix(count, 1000, s); }},
      {"music-8000", [count](std::uint32_t s) { return ToneMix(count, 8000, s); }},
      {"music-25000", [count](std::uint32_t s) { return ToneMix(count, 25000, s); }},
  };
}

}  // namespace arview::listen::testing
