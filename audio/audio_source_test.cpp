#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "audio/audio_error.h"
#include "audio/wav.h"
#include "audio/wav_source.h"

namespace arview::audio {
namespace {

using namespace std::chrono_literals;

// A clock that jumps to whatever time is slept until: a WAV of minutes is delivered at once,
// with the times a real clock would give.
class JumpingClock final : public PacingClock {
 public:
  TimePoint Now() const override {
    std::lock_guard lock(mutex_);
    return now_;
  }
  bool SleepUntil(TimePoint when, const std::stop_token& stop) override {
    std::lock_guard lock(mutex_);
    now_ = std::max(now_, when);
    return !stop.stop_requested();
  }

 private:
  mutable std::mutex mutex_;
  TimePoint now_ = TimePoint{} + 1000s;
};

struct Collected {
  std::mutex mutex;
  std::vector<std::int16_t> samples;
  std::vector<CapturedBlock> blocks;  // spans not kept valid: only first_sample and heard_at read
  std::atomic<bool> ended{false};
  SourceEnd end;

  BlockCallback OnBlock() {
    return [this](const CapturedBlock& b) {
      std::lock_guard lock(mutex);
      samples.insert(samples.end(), b.samples.begin(), b.samples.end());
      blocks.push_back(b);
    };
  }
  EndCallback OnEnd() {
    return [this](const SourceEnd& e) {
      std::lock_guard lock(mutex);
      end = e;
      ended = true;
    };
  }
};

std::vector<std::int16_t> Counting(std::size_t n) {
  std::vector<std::int16_t> samples(n);
  for (std::size_t i = 0; i < n; ++i) samples[i] = static_cast<std::int16_t>(i % 30000);
  return samples;
}

TEST(WavFileSource, DeliversEverySampleInBlocksTimedByTheClock) {
  JumpingClock clock;
  const TimePoint start = clock.Now();
  const auto samples = Counting(16000 + 100);
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  WavFileSource source(samples, clock, 320);
  source.Start(got.OnBlock(), got.OnEnd());
  source.Join();
  ASSERT_TRUE(got.ended);
  EXPECT_EQ(got.end.error, "");
  EXPECT_EQ(got.end.samples_delivered, 16100);
  EXPECT_EQ(got.samples, samples);
  ASSERT_EQ(got.blocks.size(), 51u);  // 50 full blocks and one of 100
  for (std::size_t i = 0; i < got.blocks.size(); ++i) {
    EXPECT_EQ(got.blocks[i].first_sample, static_cast<std::int64_t>(i * 320));
    EXPECT_EQ(got.blocks[i].heard_at - start, std::chrono::duration_cast<Clock::duration>(20ms * i)) << i;
  }
  // The last block was delivered once its last sample's time had come: 16100 samples = 1.00625 s.
  EXPECT_EQ(clock.Now() - start, std::chrono::duration_cast<Clock::duration>(1006250us));
  EXPECT_TRUE(source.IsTerminated());
}

TEST(WavFileSource, IsPacedToRealTimeByTheSteadyClock) {
  SteadyPacingClock clock;
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  WavFileSource source(Counting(3200), clock, 320);  // 200 ms
  const TimePoint start = Clock::now();
  source.Start(got.OnBlock(), got.OnEnd());
  source.Join();
  const auto took = Clock::now() - start;
  EXPECT_GE(took, 200ms);
  EXPECT_LT(took, 2s);  // a loaded machine's scheduling, not a pace
  EXPECT_EQ(got.samples.size(), 3200u);
}

TEST(WavFileSource, StopsBetweenBlocksWhenAskedAndStillSaysItEnded) {
  SteadyPacingClock clock;
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  WavFileSource source(Counting(16000 * 60), clock, 320);
  source.Start(got.OnBlock(), got.OnEnd());
  std::this_thread::sleep_for(50ms);
  const TimePoint asked = Clock::now();
  source.RequestStop();
  source.Join();
  EXPECT_LT(Clock::now() - asked, 1s);
  EXPECT_TRUE(got.ended);
  EXPECT_EQ(got.end.error, "");
  EXPECT_LT(got.samples.size(), 16000u * 60);
}

TEST(WavFileSource, AFileOfAnotherFormatIsRefusedOrConverted) {
  const auto file = std::filesystem::temp_directory_path() / ("arview-wavsource-" + std::to_string(::getpid()) + ".wav");
  WriteWav(file, PcmAudio{8000, 1, std::vector<std::int16_t>(800, 100)});
  JumpingClock clock;
  EXPECT_THROW(WavFileSource(file, clock), AudioError);
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  WavFileSource source(file, clock, WavSourceOptions{320, SpeechConversion::kResample});
  source.Start(got.OnBlock(), got.OnEnd());
  source.Join();
  EXPECT_EQ(got.samples.size(), 1600u);
  std::filesystem::remove(file);
}

// A source whose device fails after a few blocks, as a microphone unplugged mid-session.
class FailingSource final : public AudioSource {
 public:
  explicit FailingSource(int blocks_before_failure) : AudioSource("arview-test", 160), left_(blocks_before_failure) {}
  ~FailingSource() override { StopAndJoin(); }

 private:
  Read ReadBlock(std::span<std::int16_t> block, const std::stop_token&) override {
    if (left_-- == 0) throw AudioError("microphone 'hw:9': the device disappeared (ALSA: No such device); going on without listening");
    std::fill(block.begin(), block.end(), std::int16_t{7});
    return {block.size(), Clock::now()};
  }
  int left_;
};

TEST(AudioSource, ADeviceThatDisappearsEndsTheSourceWithItsLine) {
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  FailingSource source(3);
  source.Start(got.OnBlock(), got.OnEnd());
  source.Join();
  ASSERT_TRUE(got.ended);
  EXPECT_EQ(got.end.error, "microphone 'hw:9': the device disappeared (ALSA: No such device); going on without listening");
  EXPECT_EQ(got.end.samples_delivered, 480);
  EXPECT_TRUE(source.IsTerminated());
}

TEST(AudioSource, ACallbackThatThrowsEndsTheSourceNotTheProcess) {
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  FailingSource source(100);
  source.Start([](const CapturedBlock&) { throw std::runtime_error("recognizer: out of memory"); }, got.OnEnd());
  source.Join();
  EXPECT_EQ(got.end.error, "recognizer: out of memory");
}

TEST(AudioSource, StartingTwiceIsRefused) {
  Collected got;  // before the source: its thread calls into it until the source is destroyed
  FailingSource source(1);
  source.Start(got.OnBlock(), got.OnEnd());
  EXPECT_THROW(source.Start(got.OnBlock(), got.OnEnd()), AudioError);
}

}  // namespace
}  // namespace arview::audio
