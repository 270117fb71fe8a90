// The microphone through the emulated one (tests/support/emulated.asoundrc): ALSA's file plugin
// reading a raw file, paced to real time by AlsaCapture.
#include "audio/alsa_capture.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <mutex>

#include "audio/alsa_pcm.h"
#include "audio/audio_error.h"
#include "tests/support/emulated_sound.h"

namespace arview::audio {
namespace {

using namespace std::chrono_literals;
using testing::EmulatedSound;

std::filesystem::path Folder(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("arview-mic-" + std::to_string(::getpid()) + "-" + name);
}

TEST(AlsaCapture, DeliversTheMicrophonesSamplesPacedToRealTime) {
  EmulatedSound sound(Folder("read"));
  std::vector<std::int16_t> spoken(8000);  // half a second
  for (std::size_t i = 0; i < spoken.size(); ++i) spoken[i] = static_cast<std::int16_t>(i + 1);
  sound.SetMicrophoneInput(spoken);

  AlsaCapture mic(CaptureOptions{EmulatedSound::kMicrophone, 320});
  std::mutex mutex;
  std::vector<std::int16_t> got;
  std::vector<TimePoint> heard;
  std::vector<std::int64_t> first;
  const TimePoint start = Clock::now();
  mic.Start(
      [&](const CapturedBlock& b) {
        std::lock_guard lock(mutex);
        got.insert(got.end(), b.samples.begin(), b.samples.end());
        heard.push_back(b.heard_at);
        first.push_back(b.first_sample);
      },
      [](const SourceEnd&) {});
  while (true) {
    {
      std::lock_guard lock(mutex);
      if (got.size() >= spoken.size()) break;
    }
    std::this_thread::sleep_for(10ms);
  }
  const auto took = Clock::now() - start;
  mic.RequestStop();
  mic.Join();
  EXPECT_EQ(std::vector<std::int16_t>(got.begin(), got.begin() + 8000), spoken);
  EXPECT_GE(took, 480ms);  // paced: 25 blocks of 20 ms; the first is delivered when read
  for (std::size_t i = 1; i < heard.size(); ++i) {
    EXPECT_EQ(first[i], static_cast<std::int64_t>(i * 320));
    // Consecutive blocks were heard 20 ms apart (the emulation has no delay to jitter it).
    const double apart_ms = std::chrono::duration<double, std::milli>(heard[i] - heard[i - 1]).count();
    EXPECT_NEAR(apart_ms, 20.0, 0.01) << i;
  }
  EXPECT_EQ(mic.overruns(), 0);
}

TEST(AlsaCapture, AMissingMicrophoneIsOneLineNamingIt) {
  EmulatedSound sound(Folder("missing"));
  try {
    AlsaCapture mic(CaptureOptions{EmulatedSound::kMissing, 320});
    FAIL() << "no error";
  } catch (const AudioError& error) {
    EXPECT_EQ(std::string(error.what()),
              "microphone 'arview_no_such_device': no such device, or it cannot be opened (ALSA: No such file or directory)");
  }
}

TEST(AlsaCapture, ADeviceThatGoesAwayIsSaidSo) {
  EXPECT_EQ(PcmFaultLine(PcmDirection::kCapture, "hw:1", -ENODEV),
            "microphone 'hw:1': the device disappeared (ALSA: No such device); going on without listening");
  EXPECT_EQ(PcmFaultLine(PcmDirection::kPlayback, "hw:1", -EBADFD),
            "sound output 'hw:1': the device disappeared (ALSA: File descriptor in bad state); going on without sound");
  EXPECT_EQ(PcmFaultLine(PcmDirection::kCapture, "hw:1", -EINVAL),
            "microphone 'hw:1': failed (ALSA: Invalid argument); going on without listening");
}

}  // namespace
}  // namespace arview::audio
