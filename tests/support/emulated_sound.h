#pragma once
// Emulated ALSA devices for tests (tests/support/emulated.asoundrc): a speaker whose samples land
// in a file, and a microphone that reads one. Constructing an EmulatedSound writes the
// configuration into a folder of the test's and points ALSA_CONFIG_PATH at Debian's alsa.conf and
// it, so that the devices `arview_speaker` and `arview_mic` exist for the rest of the process.
// ALSA re-reads its configuration when ALSA_CONFIG_PATH changes, so a later EmulatedSound with
// another folder takes over.

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace arview::testing {

class EmulatedSound {
 public:
  static constexpr const char* kSpeaker = "arview_speaker";
  static constexpr const char* kSpeaker48k = "arview_speaker48k";  // behind ALSA's plug, at 48 kHz
  static constexpr const char* kMicrophone = "arview_mic";
  static constexpr const char* kMissing = "arview_no_such_device";

  explicit EmulatedSound(std::filesystem::path folder) : folder_(std::move(folder)) {
    std::filesystem::create_directories(folder_);
    std::ifstream in(SourceDir() / "tests" / "support" / "emulated.asoundrc");
    if (!in) throw std::runtime_error("cannot read tests/support/emulated.asoundrc");
    std::string config((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Replace(config, "@PLAYED@", played().string());
    Replace(config, "@PLAYED48@", played48k().string());
    Replace(config, "@SPOKEN@", spoken().string());
    const std::filesystem::path asoundrc = folder_ / "asoundrc";
    std::ofstream(asoundrc) << config;
    SetMicrophoneInput({});
    const std::string path = "/usr/share/alsa/alsa.conf:" + asoundrc.string();
    ::setenv("ALSA_CONFIG_PATH", path.c_str(), 1);
  }

  // The folder goes with the object (ALSA_CONFIG_PATH still names its configuration until the
  // next EmulatedSound: a device opened after this is gone fails to open, as a missing one does).
  ~EmulatedSound() {
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }
  EmulatedSound(const EmulatedSound&) = delete;
  EmulatedSound& operator=(const EmulatedSound&) = delete;

  // Where the speaker's samples land; what the microphone reads.
  std::filesystem::path played() const { return folder_ / "played.raw"; }
  std::filesystem::path spoken() const { return folder_ / "spoken.raw"; }
  std::filesystem::path played48k() const { return folder_ / "played48k.raw"; }

  // What the speaker received (complete once the player is destroyed: ALSA's file plugin writes
  // in periods and flushes on close).
  std::vector<std::int16_t> Played() const { return ReadRaw(played()); }
  std::vector<std::int16_t> Played48k() const { return ReadRaw(played48k()); }
  void SetMicrophoneInput(std::span<const std::int16_t> samples) const {
    std::ofstream out(spoken(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(samples.data()), static_cast<std::streamsize>(samples.size_bytes()));
  }

 private:
  static void Replace(std::string& text, const std::string& from, const std::string& to) {
    for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
  }
  static std::vector<std::int16_t> ReadRaw(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::int16_t> samples(bytes.size() / 2);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      samples[i] = static_cast<std::int16_t>(static_cast<unsigned char>(bytes[2 * i]) | (static_cast<unsigned char>(bytes[2 * i + 1]) << 8));
    }
    return samples;
  }

  std::filesystem::path folder_;
};

}  // namespace arview::testing
