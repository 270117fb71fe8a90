#include "mapping/frame_selection.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <fstream>
#include <random>

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

// A textured scene; frame i is a window shifted by `shift` pixels per frame.
cv::Mat Scene() {
  cv::Mat scene(600, 1200, CV_8UC3);
  cv::randu(scene, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(scene, scene, cv::Size(0, 0), 1.5);
  return scene;
}

cv::Mat View(const cv::Mat& scene, int x) { return scene(cv::Rect(x, 50, 320, 240)).clone(); }

cv::Mat Blurred(const cv::Mat& image) {
  cv::Mat out;
  cv::GaussianBlur(image, out, cv::Size(0, 0), 4);
  return out;
}

TEST(FrameSelection, SharpnessDropsWithBlur) {
  const cv::Mat view = View(Scene(), 0);
  EXPECT_GT(MeasureFrame(view).sharpness, 4 * MeasureFrame(Blurred(view)).sharpness);
  EXPECT_EQ(MeasureFrame(view).thumbnail.size(), cv::Size(64, 48));
}

// 40 frames moving right; frames 5 and 17 blurred; frames 10, 11, 12 identical to frame 9.
std::vector<cv::Mat> Sequence() {
  const cv::Mat scene = Scene();
  std::vector<cv::Mat> frames;
  int x = 0;
  for (int i = 0; i < 40; ++i) {
    if (i < 10 || i > 12) x += 20;
    cv::Mat f = View(scene, x);
    if (i == 5 || i == 17) f = Blurred(f);
    frames.push_back(f);
  }
  return frames;
}

TEST(FrameSelection, DropsBlurredFramesAndDuplicates) {
  std::vector<FrameQuality> q;
  std::vector<int> all;
  for (const cv::Mat& f : Sequence()) {
    all.push_back(static_cast<int>(q.size()));
    q.push_back(MeasureFrame(f));
  }
  const FrameSelection s = SelectFrames(q, all, {.max_frames = 0});
  EXPECT_EQ(s.blurred, 2);
  EXPECT_EQ(s.duplicates, 3);
  EXPECT_EQ(s.capped, 0);
  EXPECT_EQ(s.frames.size(), 35u);
  for (int dropped : {5, 10, 11, 12, 17}) {
    EXPECT_EQ(std::count(s.frames.begin(), s.frames.end(), dropped), 0) << dropped;
  }
}

TEST(FrameSelection, CapKeepsTheSharpestOfEachStretch) {
  std::vector<FrameQuality> q(20);
  std::vector<int> all;
  for (int i = 0; i < 20; ++i) {
    q[static_cast<size_t>(i)].sharpness = 100 + (i % 5 == 3 ? 50 : 0);
    q[static_cast<size_t>(i)].thumbnail = cv::Mat(48, 64, CV_8UC1, cv::Scalar(i * 10));  // all distinct
    all.push_back(i);
  }
  const FrameSelection s = SelectFrames(q, all, {.blur_ratio = 0.1, .max_frames = 4});
  EXPECT_EQ(s.frames, (std::vector<int>{3, 8, 13, 18}));
  EXPECT_EQ(s.capped, 16);
}

TEST(FrameSelection, CapEvenlySpreadsAndKeepsShortLists) {
  EXPECT_EQ(CapEvenly({0, 1, 2, 3, 4, 5, 6, 7}, 4), (std::vector<int>{0, 2, 4, 6}));
  EXPECT_EQ(CapEvenly({3, 9}, 4), (std::vector<int>{3, 9}));
  EXPECT_EQ(CapEvenly({3, 9}, 0), (std::vector<int>{3, 9}));
}

TEST(FrameSelection, ReadsAVideoRecording) {
  const fs::path dir = fs::temp_directory_path() / ("arview_frame_selection_" + std::to_string(::getpid()));
  fs::create_directories(dir / "frames");
  const fs::path video = dir / "frames" / "video.avi";
  {
    cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(320, 240));
    ASSERT_TRUE(writer.isOpened()) << "OpenCV cannot write MJPG video here";
    for (const cv::Mat& f : Sequence()) writer.write(f);
  }
  recordings::Recording rec;
  rec.root = dir;
  rec.camera = calib::Camera::Pinhole(320, 240, 300, 300, 160, 120);
  for (int i = 0; i < 40; ++i) rec.frames.push_back({0.1 * i, "frames/video.avi"});
  ASSERT_TRUE(rec.IsVideo());
  int last_done = 0;
  const FrameSelection s = SelectVideoFrames(rec, {}, {.max_frames = 10}, [&](int done, int) { last_done = done; });
  EXPECT_EQ(last_done, 40);
  EXPECT_EQ(s.blurred, 2);
  EXPECT_GE(s.duplicates, 3);  // MJPG noise could make some others look alike; never fewer
  EXPECT_EQ(s.frames.size(), 10u);
  // Candidates beyond the video's end are a clear error.
  rec.frames.push_back({4.0, "frames/video.avi"});
  EXPECT_THROW(SelectVideoFrames(rec, {40}, {}), recordings::RecordingError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview::mapping
