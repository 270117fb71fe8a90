// The player through the emulated speaker (tests/support/emulated.asoundrc): ALSA's file plugin
// over null, whose file holds every sample the player wrote, in order.
#include "audio/clip_player.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <thread>

#include "audio/audio_error.h"
#include "audio/audio_out.h"
#include "tests/support/emulated_sound.h"

namespace arview::audio {
namespace {

using namespace std::chrono_literals;
using testing::EmulatedSound;

std::filesystem::path Folder(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("arview-player-" + std::to_string(::getpid()) + "-" + name);
}

// A clip no stretch of silence can be mistaken for: no sample is 0.
std::vector<std::int16_t> Chirp(std::size_t n, double from_hz) {
  std::vector<std::int16_t> samples(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kSpeechRate;
    const double v = 12000 * std::sin(2 * std::numbers::pi * (from_hz + 400 * t) * t);
    samples[i] = static_cast<std::int16_t>(v >= 0 ? std::lround(v) + 1 : std::lround(v) - 1);
  }
  return samples;
}

// The index of the first non-zero sample at or after `from`.
std::size_t FirstSound(const std::vector<std::int16_t>& samples, std::size_t from = 0) {
  while (from < samples.size() && samples[from] == 0) ++from;
  return from;
}

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

PlayerOptions Speaker() {
  PlayerOptions options;
  options.device = EmulatedSound::kSpeaker;
  return options;
}

TEST(ClipPlayer, WritesTheClipsSamplesExactlyAtTheirTimes) {
  EmulatedSound sound(Folder("exact"));
  const auto first = Chirp(4000, 300);
  const auto second = Chirp(3000, 900);
  std::vector<ClipReport> reports;
  {
    ClipPlayer player(Speaker());
    const TimePoint start = Clock::now() + 300ms;
    player.Play(TimedClip{1, first, start});
    player.Play(TimedClip{2, second, start + 1s});  // 16000 samples after the first's start
    while (!player.Idle()) std::this_thread::sleep_for(10ms);
    reports = player.TakeReports();
    const PlayerStats stats = player.Stats();
    EXPECT_EQ(stats.clips_played, 2);
    EXPECT_EQ(stats.clips_late, 0);
    EXPECT_EQ(stats.error, "");
  }
  const auto played = sound.Played();
  const std::size_t at = FirstSound(played);
  ASSERT_LT(at + first.size(), played.size());
  EXPECT_EQ(std::vector<std::int16_t>(played.begin() + static_cast<std::ptrdiff_t>(at), played.begin() + static_cast<std::ptrdiff_t>(at + first.size())), first);
  const std::size_t at2 = FirstSound(played, at + first.size());
  EXPECT_NEAR(static_cast<double>(at2 - at), 16000.0, 1.0);  // one second on the clock is one second of samples
  ASSERT_LE(at2 + second.size(), played.size());
  EXPECT_EQ(std::vector<std::int16_t>(played.begin() + static_cast<std::ptrdiff_t>(at2), played.begin() + static_cast<std::ptrdiff_t>(at2 + second.size())), second);
  ASSERT_EQ(reports.size(), 2u);
  for (const ClipReport& r : reports) {
    // Heard on time to the sample; written before its time, by at most the lead and a period.
    std::printf("clip %llu: heard %+.3f ms, written %+.3f ms from its time\n", static_cast<unsigned long long>(r.id),
                Ms(r.heard - r.scheduled), Ms(r.written - r.scheduled));
    EXPECT_LE(std::abs(Ms(r.heard - r.scheduled)), 1000.0 / kSpeechRate);
    EXPECT_LT(r.written, r.scheduled);
    EXPECT_LT(Ms(r.scheduled - r.written), 100 + 10 + 5);
    EXPECT_FALSE(r.late);
  }
}

// Through ALSA's plug at 48 kHz (as `default` usually is): the device takes 16 kHz, ALSA converts,
// and the clip's place and length come out three times as many samples.
TEST(ClipPlayer, ADeviceAtAnotherRateIsConvertedByAlsa) {
  EmulatedSound sound(Folder("plug"));
  const auto clip = Chirp(8000, 400);
  {
    PlayerOptions options;
    options.device = EmulatedSound::kSpeaker48k;
    ClipPlayer player(options);
    const TimePoint start = Clock::now() + 300ms;
    player.Play(TimedClip{1, clip, start});
    player.Play(TimedClip{2, clip, start + 1s});
    while (!player.Idle()) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(player.Stats().error, "");
    EXPECT_EQ(player.Stats().underruns, 0);
  }
  const auto played = sound.Played48k();
  // Each clip is a run of sound of about 3 x 8000 samples; the two start 48000 apart.
  std::vector<std::size_t> starts;
  std::size_t at = 0;
  while ((at = FirstSound(played, at)) < played.size()) {
    std::size_t end = at;
    std::size_t silent = 0;
    while (end < played.size() && silent < 48) silent = played[end++] == 0 ? silent + 1 : 0;
    if (end - at > 1000) starts.push_back(at);
    at = end;
  }
  ASSERT_EQ(starts.size(), 2u);
  EXPECT_NEAR(static_cast<double>(starts[1] - starts[0]), 48000.0, 3.0);
}

TEST(ClipPlayer, OverlappingClipsAreMixed) {
  EmulatedSound sound(Folder("mix"));
  {
    ClipPlayer player(Speaker());
    const TimePoint start = Clock::now() + 200ms;
    player.Play(TimedClip{1, std::vector<std::int16_t>(1600, 1000), start});
    player.Play(TimedClip{2, std::vector<std::int16_t>(1600, 30000), start + 50ms});  // 800 samples in
    while (!player.Idle()) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(100ms);  // silence after them
  }
  const auto played = sound.Played();
  const std::size_t at = FirstSound(played);
  ASSERT_LT(at + 2400, played.size());
  EXPECT_EQ(played[at], 1000);
  EXPECT_EQ(played[at + 799], 1000);
  EXPECT_EQ(played[at + 800], 31000);
  EXPECT_EQ(played[at + 1599], 31000);
  EXPECT_EQ(played[at + 1600], 30000);
  EXPECT_EQ(played[at + 2399], 30000);
  EXPECT_EQ(played[at + 2400], 0);
}

TEST(ClipPlayer, AClipWhoseTimeHasPassedStartsAtOnceAndIsReportedLate) {
  EmulatedSound sound(Folder("late"));
  ClipPlayer player(Speaker());
  const TimePoint due = Clock::now() - 500ms;
  player.Play(TimedClip{7, Chirp(800, 500), due});
  while (!player.Idle()) std::this_thread::sleep_for(10ms);
  const auto reports = player.TakeReports();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_TRUE(reports[0].late);
  EXPECT_GT(reports[0].heard - due, 400ms);
  EXPECT_EQ(player.Stats().clips_late, 1);
}

// Continuous clips back to back for ARVIEW_AUDIO_SOAK_SECONDS (5 by default; docs/audio.md has
// the two-minute run's figures): no underrun, every clip on time.
TEST(ClipPlayer, ContinuousClipsNeverUnderrun) {
  const char* env = std::getenv("ARVIEW_AUDIO_SOAK_SECONDS");
  const int seconds = env != nullptr ? std::atoi(env) : 5;
  EmulatedSound sound(Folder("soak"));
  ClipPlayer player(Speaker());
  const TimePoint start = Clock::now() + 200ms;
  // One-second clips, each queued half a second before it is due, as a speech queue would.
  double worst_heard_ms = 0;
  double worst_written_early_ms = 0;
  double least_written_early_ms = 1e9;
  for (int i = 0; i < seconds; ++i) {
    std::this_thread::sleep_until(start + i * 1s - 500ms);
    player.Play(TimedClip{static_cast<std::uint64_t>(i), Chirp(16000, 200 + 50 * (i % 10)), start + i * 1s});
    for (const ClipReport& r : player.TakeReports()) {
      worst_heard_ms = std::max(worst_heard_ms, std::abs(Ms(r.heard - r.scheduled)));
      worst_written_early_ms = std::max(worst_written_early_ms, Ms(r.scheduled - r.written));
      least_written_early_ms = std::min(least_written_early_ms, Ms(r.scheduled - r.written));
    }
  }
  while (!player.Idle()) std::this_thread::sleep_for(10ms);
  for (const ClipReport& r : player.TakeReports()) worst_heard_ms = std::max(worst_heard_ms, std::abs(Ms(r.heard - r.scheduled)));
  const PlayerStats stats = player.Stats();
  std::printf("%d s of clips: %lld underruns, %lld late, %lld frames written, worst |heard - due| %.3f ms, "
              "written %.1f to %.1f ms before due, least queued %.1f ms\n",
              seconds, static_cast<long long>(stats.underruns), static_cast<long long>(stats.clips_late),
              static_cast<long long>(stats.frames_written), worst_heard_ms, least_written_early_ms, worst_written_early_ms,
              Ms(stats.least_queued));
  EXPECT_EQ(stats.underruns, 0);
  EXPECT_EQ(stats.clips_late, 0);
  EXPECT_EQ(stats.clips_played, seconds);
  EXPECT_LE(worst_heard_ms, 1000.0 / kSpeechRate);
}

TEST(ClipPlayer, AMissingDeviceIsOneLineNamingIt) {
  EmulatedSound sound(Folder("missing"));
  PlayerOptions options;
  options.device = EmulatedSound::kMissing;
  try {
    ClipPlayer player(options);
    FAIL() << "no error";
  } catch (const AudioError& error) {
    EXPECT_EQ(std::string(error.what()),
              "sound output 'arview_no_such_device': no such device, or it cannot be opened (ALSA: No such file or directory)");
  }
}

TEST(AudioOut, NoDeviceMeansOneLineAndSilenceNotAnError) {
  EmulatedSound sound(Folder("out"));
  const OpenedAudioOut missing = OpenAudioOut(ParseAudioOut(EmulatedSound::kMissing));
  EXPECT_EQ(missing.player, nullptr);
  EXPECT_EQ(missing.note,
            "no sound: sound output 'arview_no_such_device': no such device, or it cannot be opened (ALSA: No such file or "
            "directory); going on silent");
  const OpenedAudioOut none = OpenAudioOut(ParseAudioOut("none"));
  EXPECT_EQ(none.player, nullptr);
  EXPECT_EQ(none.note, "");
  const OpenedAudioOut speaker = OpenAudioOut(ParseAudioOut(EmulatedSound::kSpeaker));
  EXPECT_NE(speaker.player, nullptr);
  EXPECT_EQ(speaker.note, "");
}

TEST(AudioOut, TheFlagsValues) {
  EXPECT_FALSE(ParseAudioOut("none").enabled);
  EXPECT_EQ(ParseAudioOut("default").device, "default");
  EXPECT_EQ(ParseAudioOut("plughw:CARD=USB,DEV=0").device, "plughw:CARD=USB,DEV=0");
  EXPECT_THROW(ParseAudioOut(""), AudioError);
  EXPECT_THROW(ParseAudioOut("hw:1 0"), AudioError);
  EXPECT_THROW(ParseAudioOut(std::string("hw\x01", 3)), AudioError);
}

TEST(ClipPlayer, ALeadShorterThanAPeriodIsRefused) {
  PlayerOptions options = Speaker();
  options.lead = 5ms;
  EXPECT_THROW(ClipPlayer player(options), AudioError);
}

}  // namespace
}  // namespace arview::audio
