#include "recordings/frame_source.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "recordings/importers.h"
#include "recordings/test_helpers.h"

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

// A recording of `n` distinct 64x48 still frames, 0.02 s apart.
Recording MakeStillRecording(const fs::path& root, int n) {
  fs::create_directories(root / "frames");
  std::vector<FrameEntry> frames;
  for (int i = 0; i < n; ++i) {
    const std::string rel = "frames/" + std::to_string(100 + i) + ".png";
    test::WriteImage(root / rel, 64, 48, i);
    frames.push_back({10.0 + 0.02 * i, rel});
  }
  calib::SaveCamera(calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5), root / "camera.yaml");
  WriteFramesTxt(root, frames);
  return LoadRecording(root);
}

TEST(RecordingSource, ReplaysStillFramesInOrder) {
  TempDir dir("replay");
  RecordingSource source(MakeStillRecording(dir.path() / "rec", 5));
  Frame f;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source.Next(f));
    EXPECT_EQ(f.index, i);
    EXPECT_NEAR(f.timestamp, 10.0 + 0.02 * i, 1e-9);
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(f.image, test::MakeImage(64, 48, i), cv::NORM_INF), 0);
  }
  EXPECT_FALSE(source.Next(f));
  EXPECT_FALSE(source.Next(f));
}

TEST(RecordingSource, LoopsWithIncreasingTimestampsAndSelectsFrames) {
  TempDir dir("replay_loop");
  ReplayOptions options;
  options.loop = true;
  options.frames = {1, 3};
  RecordingSource source(MakeStillRecording(dir.path() / "rec", 5), options);
  Frame f;
  std::vector<int64_t> indices;
  std::vector<double> stamps;
  for (int k = 0; k < 6; ++k) {
    ASSERT_TRUE(source.Next(f));
    indices.push_back(f.index);
    stamps.push_back(f.timestamp);
  }
  EXPECT_EQ(indices, (std::vector<int64_t>{1, 3, 1, 3, 1, 3}));
  // A pass lasts last - first + one interval: 0.04 + 0.04.
  EXPECT_NEAR(stamps[2] - stamps[0], 0.08, 1e-9);
  EXPECT_NEAR(stamps[5] - stamps[3], 0.08, 1e-9);
  for (size_t k = 1; k < stamps.size(); ++k) EXPECT_GT(stamps[k], stamps[k - 1]);
}

// `arview replay --loop N`: N passes over the selection, then the end of the stream.
TEST(RecordingSource, StopsAfterTheGivenNumberOfPasses) {
  TempDir dir("replay_passes");
  ReplayOptions options;
  options.loop = true;
  options.passes = 3;
  options.frames = {0, 2};
  RecordingSource source(MakeStillRecording(dir.path() / "rec", 4), options);
  Frame f;
  std::vector<int64_t> indices;
  while (source.Next(f)) indices.push_back(f.index);
  EXPECT_EQ(indices, (std::vector<int64_t>{0, 2, 0, 2, 0, 2}));
  EXPECT_FALSE(source.Next(f));
}

TEST(RecordingSource, PacedReplayWaitsForTheRecordedTimes) {
  TempDir dir("replay_paced");
  ReplayOptions options;
  options.paced = true;
  RecordingSource source(MakeStillRecording(dir.path() / "rec", 6), options);
  Frame f;
  const auto start = std::chrono::steady_clock::now();
  int n = 0;
  while (source.Next(f)) ++n;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(n, 6);
  EXPECT_GE(elapsed, 0.1 - 1e-3);  // frame 5 is due 5 × 0.02 s after frame 0: a lower bound only
}

// Paced, frames are read ahead on the source's own thread: the same frames, in order, at their times.
TEST(RecordingSource, PacedReadAheadDeliversEveryFrameInOrderAtItsTime) {
  TempDir dir("replay_ahead");
  const Recording rec = MakeStillRecording(dir.path() / "rec", 6);
  for (const int read_ahead : {0, 1, 3}) {
    ReplayOptions options;
    options.paced = true;
    options.read_ahead = read_ahead;
    RecordingSource source(rec, options);
    Frame f;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 6; ++i) {
      ASSERT_TRUE(source.Next(f)) << read_ahead;
      EXPECT_EQ(f.index, i);
      EXPECT_NEAR(f.timestamp, 10.0 + 0.02 * i, 1e-9);
      EXPECT_EQ(cv::norm(f.image, test::MakeImage(64, 48, i), cv::NORM_INF), 0);
      // Its capture time is its due time, whenever it was read.
      EXPECT_NEAR(std::chrono::duration<double>(f.capture_time - start).count(), 0.02 * i, 0.015) << read_ahead;
    }
    EXPECT_FALSE(source.Next(f));
    EXPECT_FALSE(source.Next(f));
  }
}

// The frames are read from the source's construction on: frames already read are delivered
// though their files are gone, and a frame that cannot be read stops the replay, naming its
// file, after every frame before it.
TEST(RecordingSource, ReadAheadReadsBeforeTheFramesAreDueAndReportsAFailureInItsPlace) {
  TempDir dir("replay_ahead_read");
  const Recording rec = MakeStillRecording(dir.path() / "rec", 7);
  ReplayOptions options;
  options.paced = true;
  options.read_ahead = 4;
  RecordingSource source(rec, options);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // 4 frames of 64x48 read long since
  for (int i = 0; i < 4; ++i) fs::remove(rec.FramePath(i));
  fs::remove(rec.FramePath(5));
  Frame f;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source.Next(f));
    EXPECT_EQ(f.index, i);
  }
  try {
    source.Next(f);
    ADD_FAILURE() << "the missing frame 5 was not reported";
  } catch (const SourceError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(rec.FramePath(5).string() + ": ", 0), 0u) << e.what();
  }
}

// A looping replay stopped partway: the read-ahead thread is stopped and joined.
TEST(RecordingSource, ReadAheadStopsWithTheSource) {
  TempDir dir("replay_ahead_stop");
  const Recording rec = MakeStillRecording(dir.path() / "rec", 3);
  ReplayOptions options;
  options.paced = true;
  options.loop = true;
  options.speed = 10;
  auto source = std::make_unique<RecordingSource>(rec, options);
  Frame f;
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(source->Next(f));
  const auto start = std::chrono::steady_clock::now();
  source.reset();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(RecordingSource, ReplaysAVideoRecording) {
  TempDir dir("replay_video");
  ASSERT_TRUE(test::WriteTestVideo(dir.path() / "clip.avi", 8, 25.0));
  ImportOptions io;
  io.camera = calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5);
  ImportVideo(dir.path() / "clip.avi", dir.path() / "rec", io);
  ReplayOptions options;
  options.loop = true;
  RecordingSource source(LoadRecording(dir.path() / "rec"), options);
  Frame f;
  for (int k = 0; k < 11; ++k) {  // one pass and then some: the video is reopened
    ASSERT_TRUE(source.Next(f));
    EXPECT_EQ(f.index, k % 8);
    ASSERT_EQ(f.image.size(), cv::Size(64, 48));
    // MJPEG is lossy; the frame must still be far closer to its own source than to another.
    const double own = cv::norm(f.image, test::MakeImage(64, 48, k % 8), cv::NORM_L1);
    const double other = cv::norm(f.image, test::MakeImage(64, 48, (k + 1) % 8), cv::NORM_L1);
    EXPECT_LT(own, 0.5 * other) << "frame " << k;
  }
  // Jumping backwards within a pass works too.
  options.loop = false;
  options.frames = {5, 2};
  RecordingSource jump(LoadRecording(dir.path() / "rec"), options);
  ASSERT_TRUE(jump.Next(f));
  EXPECT_EQ(f.index, 5);
  ASSERT_TRUE(jump.Next(f));
  EXPECT_EQ(f.index, 2);
  EXPECT_LT(cv::norm(f.image, test::MakeImage(64, 48, 2), cv::NORM_L1),
            0.5 * cv::norm(f.image, test::MakeImage(64, 48, 3), cv::NORM_L1));
}

TEST(RecordingSource, NamesTheFileWhenAFrameIsUnreadableOrTheVideoIsShort) {
  TempDir dir("replay_bad");
  Recording rec = MakeStillRecording(dir.path() / "rec", 3);
  test::WriteFile(dir.path() / "rec/frames/101.png", "garbage");
  RecordingSource source(rec);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  try {
    source.Next(f);
    FAIL() << "expected a SourceError";
  } catch (const SourceError& e) {
    EXPECT_NE(std::string(e.what()).find("101.png"), std::string::npos) << e.what();
  }
  // A video with fewer frames than frames.txt lists.
  ASSERT_TRUE(test::WriteTestVideo(dir.path() / "clip.avi", 4, 25.0));
  ImportOptions io;
  io.camera = calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5);
  ImportVideo(dir.path() / "clip.avi", dir.path() / "vid", io);
  std::vector<FrameEntry> frames = LoadRecording(dir.path() / "vid").frames;
  frames.push_back({frames.back().timestamp + 1, frames.back().path});
  WriteFramesTxt(dir.path() / "vid", frames);
  RecordingSource video(LoadRecording(dir.path() / "vid"));
  for (int k = 0; k < 4; ++k) ASSERT_TRUE(video.Next(f));
  EXPECT_THROW(video.Next(f), SourceError);
  ReplayOptions bad;
  bad.frames = {7};
  EXPECT_THROW(RecordingSource(LoadRecording(dir.path() / "vid"), bad), SourceError);
}

// Issue 17: a frame deleted, or cut short (still being copied), after the recording was loaded
// and before the replay reaches it. The replay stops at that frame with one SourceError naming
// the file (the frames before it were delivered); libpng prints nothing of its own.
TEST(RecordingSource, AFrameDeletedOrTruncatedMidReplayStopsItNamingTheFile) {
  TempDir dir("replay_vanish");
  const Recording rec = MakeStillRecording(dir.path() / "rec", 4);
  for (const bool truncate : {false, true}) {
    RecordingSource source(rec);
    Frame f;
    ASSERT_TRUE(source.Next(f));
    const fs::path victim = rec.FramePath(1);
    if (truncate) {
      test::WriteImage(victim, 64, 48, 1);
      const auto size = fs::file_size(victim);
      fs::resize_file(victim, size / 2);
    } else {
      fs::remove(victim);
    }
    ::testing::internal::CaptureStderr();
    std::string message;
    try {
      source.Next(f);
    } catch (const SourceError& e) {
      message = e.what();
    }
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << truncate;
    EXPECT_EQ(message.rfind(victim.string() + ": ", 0), 0u) << truncate << ": " << message;
  }
}

// Issue 17: frames.txt naming a file outside the recording was loaded and handed to COLMAP.
TEST(LoadRecording, FramePathsOutsideTheFolderAreRefused) {
  TempDir dir("outside");
  MakeStillRecording(dir.path() / "rec", 2);
  test::WriteImage(dir.path() / "other.png", 64, 48, 0);
  fs::create_symlink(dir.path() / "other.png", dir.path() / "rec" / "frames" / "link.png");
  for (const std::string bad : {"../../../../etc/passwd", "/etc/passwd", "../other.png", "frames/link.png"}) {
    WriteFramesTxt(dir.path() / "rec", {{0.0, "frames/100.png"}, {1.0, bad}});
    try {
      LoadRecording(dir.path() / "rec");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const RecordingError& e) {
      EXPECT_NE(std::string(e.what()).find("points outside"), std::string::npos) << bad << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find("frames.txt"), std::string::npos) << e.what();
    }
  }
}

// Issue 41: a NUL byte in a frame path cut the message to "arview: rec/frames/". It is refused
// naming frames.txt and the line, the whole path shown with the NUL escaped; other control
// characters alike.
TEST(LoadRecording, AControlCharacterInAFramePathIsRefusedWithTheLineAndThePathEscaped) {
  TempDir dir("nul");
  MakeStillRecording(dir.path() / "rec", 2);
  const fs::path frames_txt = dir.path() / "rec" / "frames.txt";
  for (const char control : {'\0', '\x1b', '\x7f'}) {
    {
      std::ofstream out(frames_txt, std::ios::binary | std::ios::trunc);
      out << "# timestamp path\n0 frames/100.png\n1 frames/" << control << "evil.png\n";
    }
    char escaped[8];
    std::snprintf(escaped, sizeof escaped, "\\x%02x", static_cast<unsigned char>(control));
    try {
      LoadRecording(dir.path() / "rec");
      ADD_FAILURE() << "a path holding " << escaped << " was accepted";
    } catch (const RecordingError& e) {
      const std::string message = e.what();  // what() is read up to its first NUL, as main prints it
      EXPECT_EQ(message, frames_txt.string() + ":3: the frame path 'frames/" + escaped +
                             "evil.png' holds the control character " + escaped + " (a frame path is printable text)");
    }
  }
}

// Issue 17: a frames.txt that is a FIFO (or a link to /dev/zero) hung the reader.
TEST(LoadRecording, AFramesTxtThatIsNotARegularFileIsRefusedAtOnce) {
  TempDir dir("fifo");
  MakeStillRecording(dir.path() / "rec", 2);
  fs::remove(dir.path() / "rec" / "frames.txt");
  fs::create_symlink("/dev/zero", dir.path() / "rec" / "frames.txt");
  EXPECT_THROW(LoadRecording(dir.path() / "rec"), RecordingError);
}

}  // namespace
}  // namespace arview::recordings
