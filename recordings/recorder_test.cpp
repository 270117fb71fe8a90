#include "recordings/recorder.h"

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>

#include <cerrno>
#include <cstring>

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
  const RecordStats stats = RecordFrames(source, writer, 0, stop, [&](const Frame&, const RecordStats&) { ++calls; });
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

// Issue 17 §6: the disk fills while recording (a 64 KiB tmpfs; 64x48 frames of about 9 KB). The
// frame that does not fit is one RecordingError naming the file; what was recorded before it
// stays a valid recording: every frame listed is on disk whole, nothing else is left in frames/.
TEST(RecordFrames, ADiskThatFillsMidRecordingLeavesAValidRecordingOfTheFramesBefore) {
  TempDir dir("record_full");
  const fs::path mount_point = dir.path() / "small";
  fs::create_directories(mount_point);
  if (::mount("tmpfs", mount_point.c_str(), "tmpfs", 0, "size=64k") != 0) {
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root and the right to mount): " << std::strerror(errno);
  }
  struct Unmount {
    fs::path at;
    ~Unmount() { ::umount(at.c_str()); }
  } unmount{mount_point};
  FakeSource source(100);
  RecordingWriter writer(mount_point / "rec", SmallCamera(), false);
  std::string error;
  try {
    RecordFrames(source, writer, 0, {});
  } catch (const RecordingError& e) {
    error = e.what();
  }
  ASSERT_NE(error, "") << "100 frames fitted in 64 KiB";
  EXPECT_EQ(error.rfind((mount_point / "rec").string(), 0), 0u) << error;
  EXPECT_NE(error.find("No space left on device"), std::string::npos) << error;
  const Recording rec = LoadRecording(mount_point / "rec");
  EXPECT_GT(rec.frames.size(), 0u);
  EXPECT_EQ(static_cast<int>(rec.frames.size()), writer.frame_count());
  for (size_t i = 0; i < rec.frames.size(); ++i) {
    EXPECT_EQ(cv::norm(rec.ReadImage(static_cast<int>(i)), test::MakeImage(64, 48, static_cast<int>(i)), cv::NORM_INF), 0) << i;
  }
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(mount_point / "rec/frames")) files += e.is_regular_file();
  EXPECT_EQ(files, rec.frames.size());
}

// The same when frames.txt is the file that hits the limit, part-way through a line: 1x1 frames
// (a PNG of about 70 bytes) and a file-size limit of 1000 bytes (RLIMIT_FSIZE, SIGXFSZ ignored,
// in a child process), so that the append of line 30-odd is written only in part. That part is
// cut off again and the frame's PNG removed: frames.txt lists only whole frames.
TEST(RecordingWriter, AFramesTxtLineCutShortByAFullDiskIsTakenBackWithItsFrame) {
  TempDir dir("writer_short");
  const fs::path root = dir.path() / "rec";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{1000, 1000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int status = 1;  // no error at all
    try {
      RecordingWriter writer(root, std::nullopt, false);
      for (int i = 0; i < 1000; ++i) writer.Append(cv::Mat(1, 1, CV_8UC3, cv::Scalar(i % 256, 7, 9)), i / 30.0);
    } catch (const RecordingError& e) {
      const std::string what = e.what();
      status = what.rfind((root / "frames.txt").string() + ": cannot write (only ", 0) == 0 ? 0 : 2;
      if (status != 0) std::fprintf(stderr, "%s\n", what.c_str());
    } catch (...) {
      status = 3;
    }
    ::_exit(status);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "1: no error; 2: another error than a short write of frames.txt; 3: not a RecordingError";
  calib::SaveCamera(calib::Camera::Pinhole(1, 1, 1, 1, 0, 0), root / "camera.yaml");
  const Recording rec = LoadRecording(root);
  EXPECT_GT(rec.frames.size(), 10u);
  for (size_t i = 0; i < rec.frames.size(); ++i) {
    EXPECT_EQ(rec.ReadImage(static_cast<int>(i)).at<cv::Vec3b>(0, 0)[0], i % 256) << i;
  }
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(root / "frames")) files += e.is_regular_file();
  EXPECT_EQ(files, rec.frames.size());
}

}  // namespace
}  // namespace arview::recordings
