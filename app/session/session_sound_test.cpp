// SessionSound's heard audio (issue 54, `replay --dialogue --audio-in --out x.mp4`): the WAV the
// dialogue hears goes into the video's audio track once, its sample 0 at frame time 0, and a
// video without a track gets nothing.

#include "app/session/session_sound.h"

#include <gtest/gtest.h>

#include <utility>

namespace arview::app {
namespace {

// A file sink that keeps what it was asked to write into its audio track.
class AudioRecordingSink final : public video::FrameSink {
 public:
  explicit AudioRecordingSink(bool has_audio) : has_audio_(has_audio) {}
  void Write(const cv::Mat&) override {}
  void Close() override {}
  std::string Describe() const override { return "test sink"; }
  bool HasAudio() const override { return has_audio_; }
  void WriteAudio(std::int64_t first_sample, std::span<const std::int16_t> samples) override {
    writes.emplace_back(first_sample, std::vector<std::int16_t>(samples.begin(), samples.end()));
  }
  std::vector<std::pair<std::int64_t, std::vector<std::int16_t>>> writes;

 private:
  bool has_audio_;
};

FrameLog FrameAt(double animation_s) {
  FrameLog f;
  f.captured_s = animation_s;
  f.animation_s = animation_s;
  return f;
}

TEST(SessionSound, TheHeardWavGoesIntoTheVideoOnceFromFrameTimeZero) {
  AudioRecordingSink sink(true);
  SessionSound sound(nullptr, sink, 30);
  const std::vector<std::int16_t> heard(16000, 7);  // one second
  sound.AddHeardAudio(heard);
  for (int k = 0; k < 5; ++k) sound.OnFrameShown(FrameAt(k / 30.0), Clock::now());
  ASSERT_EQ(sink.writes.size(), 1u);
  EXPECT_EQ(sink.writes[0].first, 0);
  EXPECT_EQ(sink.writes[0].second, heard);
  const SoundReport report = sound.Finish();
  EXPECT_DOUBLE_EQ(report.heard_in_video_s, 1.0);
  EXPECT_NE(SoundSummaryText(report).find("with the 1.0 s heard (--audio-in)"), std::string::npos) << SoundSummaryText(report);
}

TEST(SessionSound, TheHeardWavWaitsForTheFirstAnimatedFrameAndIsPlacedAtItsTimeZero) {
  AudioRecordingSink sink(true);
  SessionSound sound(nullptr, sink, 30);
  sound.AddHeardAudio(std::vector<std::int16_t>(320, 1));
  sound.OnFrameShown(FrameAt(-1), Clock::now());  // a frame before the characters were animated
  EXPECT_TRUE(sink.writes.empty());
  sound.OnFrameShown(FrameAt(0.0), Clock::now());  // the video's second frame, at 1/30 s
  ASSERT_EQ(sink.writes.size(), 1u);
  EXPECT_EQ(sink.writes[0].first, 533);  // 1/30 s at 16 kHz
}

TEST(SessionSound, AVideoWithoutATrackGetsNoHeardAudio) {
  AudioRecordingSink sink(false);
  SessionSound sound(nullptr, sink, 30);
  sound.AddHeardAudio(std::vector<std::int16_t>(16000, 7));
  sound.OnFrameShown(FrameAt(0), Clock::now());
  EXPECT_TRUE(sink.writes.empty());
  EXPECT_EQ(sound.Finish().heard_in_video_s, 0.0);
}

}  // namespace
}  // namespace arview::app
