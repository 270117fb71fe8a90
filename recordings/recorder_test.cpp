#include "recordings/recorder.h"

#include <gtest/gtest.h>

#include "recordings/test_helpers.h"

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

calib::Camera SmallCamera() { return calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5); }

// A FrameSource of synthetic frames at 30 Hz that can raise a stop flag after some frames, and
// can repeat a timestamp once to imitate a driver glitch.
class FakeSource : public FrameSource {
 public:
  FakeSource(int n, const CancellationToken* stop_after = nullptr, int stop_at = -1, int repeat_at = -1)
      : n_(n), stop_(stop_after), stop_at_(stop_at), repeat_at_(repeat_at) {}
  bool Next(Frame& f) override {
    if (i_ == n_) return false;
    if (i_ == stop_at_ && stop_) stop_->Cancel(SIGINT);
    f.image = test::MakeImage(64, 48, i_);
    f.timestamp = 1000.0 + (i_ == repeat_at_ ? i_ - 1 : i_) / 30.0;
    f.index = i_++;
    return true;
  }
  std::string Name() const override { return "fake"; }

 private:
  int n_, i_ = 0;
  const CancellationToken* stop_;
  int stop_at_, repeat_at_;
};

TEST(RecordingWriter, WritesAValidRecordingFrameByFrame) {
  TempDir dir("writer");
  RecordingWriter writer(dir.path() / "rec", SmallCamera(), false);
  writer.Append(test::MakeImage(64, 48, 0), 0.0);
  // After every frame the folder is already a valid recording.
  EXPECT_EQ(LoadRecording(dir.path() / "rec").frames.size(), 1u);
  writer.Append(test::MakeImage(64, 48, 1), 0.033);
  EXPECT_THROW(writer.Append(test::MakeImage(64, 48, 2), 0.033), RecordingError);  // not increasing
  EXPECT_THROW(writer.Append(test::MakeImage(32, 48, 2), 0.1), RecordingError);    // wrong size
  const Recording rec = LoadRecording(dir.path() / "rec");
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.frames[1].path, "frames/000001.png");
  EXPECT_NEAR(rec.frames[1].timestamp, 0.033, 1e-9);
  EXPECT_EQ(cv::norm(rec.ReadImage(1), test::MakeImage(64, 48, 1), cv::NORM_INF), 0);
  // No temporary files are left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir.path() / "rec/frames")) files += e.is_regular_file();
  EXPECT_EQ(files, 2);
}

TEST(RecordFrames, StopsOnTheFlagAndLeavesAConsistentRecording) {
  TempDir dir("record_stop");
  const CancellationToken stop;
  FakeSource source(100, &stop, 12);
  RecordingWriter writer(dir.path() / "rec", SmallCamera(), false);
  int calls = 0;
  const RecordStats stats = RecordFrames(source, writer, 0, stop, [&](const RecordStats&) { ++calls; });
  // The flag rose while frame 12 was delivered: that frame is kept, nothing after it.
  EXPECT_EQ(stats.frames, 13);
  EXPECT_EQ(calls, 13);
  const Recording rec = LoadRecording(dir.path() / "rec");
  EXPECT_EQ(rec.frames.size(), 13u);
  EXPECT_DOUBLE_EQ(rec.frames[0].timestamp, 0.0);
}

TEST(RecordFrames, StopsAfterTheRequestedSpanAndSkipsRepeatedTimestamps) {
  TempDir dir("record_span");
  FakeSource source(100, nullptr, -1, 5);
  RecordingWriter writer(dir.path() / "rec", std::nullopt, false);
  const RecordStats stats = RecordFrames(source, writer, 1.0, {});
  EXPECT_EQ(stats.skipped, 1);
  EXPECT_EQ(stats.frames, 29);  // t = 0 .. 29/30 s, minus the repeated one
  EXPECT_FALSE(fs::exists(dir.path() / "rec/camera.yaml"));
  EXPECT_THROW(LoadRecording(dir.path() / "rec"), RecordingError);  // needs a camera.yaml first
  calib::SaveCamera(SmallCamera(), dir.path() / "rec/camera.yaml");
  EXPECT_EQ(LoadRecording(dir.path() / "rec").frames.size(), 29u);
}

TEST(RecordingWriter, RemovesWhatItCreatedWhenNothingWasRecorded) {
  TempDir dir("writer_empty");
  RecordingWriter empty(dir.path() / "rec", SmallCamera(), false);
  EXPECT_TRUE(empty.RemoveIfEmpty());
  EXPECT_FALSE(fs::exists(dir.path() / "rec"));
  EXPECT_THROW(empty.Append(test::MakeImage(64, 48, 0), 0.0), RecordingError);
  RecordingWriter one(dir.path() / "rec2", SmallCamera(), false);
  one.Append(test::MakeImage(64, 48, 0), 0.0);
  EXPECT_FALSE(one.RemoveIfEmpty());
  EXPECT_EQ(LoadRecording(dir.path() / "rec2").frames.size(), 1u);
}

}  // namespace
}  // namespace arview::recordings
