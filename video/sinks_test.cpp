#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "video/video_error.h"
#include "video/sinks.h"

namespace arview::video {
namespace {

namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_sinks_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

cv::Mat Frame(int i) {
  cv::Mat m(120, 160, CV_8UC3, cv::Scalar(40, 80, 120));
  cv::circle(m, {20 + 10 * i, 60}, 15, cv::Scalar(255, 255, 255), -1);
  return m;
}

TEST(Sinks, AnMp4OpenedWithAudioTakesItAndOtherSinksRefuseItNamingThemselves) {
  const fs::path file = Scratch("with-audio.mp4");
  auto sink = OpenSink(file.string(), {160, 120}, 25.0, {}, AudioTrackOptions{});
  ASSERT_TRUE(sink->HasAudio());
  EXPECT_NE(sink->Describe().find("AAC"), std::string::npos);
  sink->WriteAudio(0, std::vector<std::int16_t>(1600, 1000));
  for (int i = 0; i < 5; ++i) sink->Write(Frame(i));
  sink->Close();
  EXPECT_EQ(sink->AudioSamplesDropped(), 0);
  auto plain = OpenSink(Scratch("plain.mp4").string(), {160, 120}, 25.0);
  EXPECT_FALSE(plain->HasAudio());
  auto null_sink = OpenSink("null", {160, 120}, 25.0, {}, AudioTrackOptions{});
  EXPECT_FALSE(null_sink->HasAudio());
  try {
    null_sink->WriteAudio(0, std::vector<std::int16_t>(10, 1));
    FAIL() << "no error";
  } catch (const VideoError& error) {
    EXPECT_EQ(std::string(error.what()), null_sink->Describe() + ": has no audio track");
  }
}

TEST(Sinks, Mp4FileReadsBackWithEveryFrame) {
  const fs::path file = Scratch("out.mp4");
  {
    auto sink = OpenSink(file.string(), {160, 120}, 30);
    for (int i = 0; i < 10; ++i) sink->Write(Frame(i));
    sink->Close();
  }
  cv::VideoCapture in(file.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(in.isOpened());
  int frames = 0;
  cv::Mat m;
  while (in.read(m)) {
    EXPECT_EQ(m.size(), cv::Size(160, 120));
    ++frames;
  }
  EXPECT_EQ(frames, 10);
  fs::remove_all(file.parent_path());
}

// The H.264 file (libx264 at its superfast preset, video/h264_writer.h): every frame comes back
// where it was, close to what was written, and the stream says which x264 settings made it.
TEST(Sinks, Mp4IsH264AtTheFastPresetAndKeepsThePicture) {
  const fs::path file = Scratch("fast.mp4");
  {
    auto sink = OpenSink(file.string(), {160, 120}, 30);
    EXPECT_NE(sink->Describe().find("libx264 superfast"), std::string::npos) << sink->Describe();
    for (int i = 0; i < 10; ++i) sink->Write(Frame(i));
    sink->Close();
    sink->Close();  // twice is safe
  }
  cv::VideoCapture in(file.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(in.isOpened());
  EXPECT_NEAR(in.get(cv::CAP_PROP_FPS), 30.0, 1e-6);
  int frames = 0;
  cv::Mat m;
  while (in.read(m)) {
    // Mean absolute difference per channel: the disc moved by 10 px a frame, so a frame out of
    // order or a lost one differs by far more than compression does.
    cv::Mat diff;
    cv::absdiff(m, Frame(frames), diff);
    EXPECT_LT(cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2], 3 * 4.0) << "frame " << frames;
    ++frames;
  }
  EXPECT_EQ(frames, 10);
  // x264 writes its settings into the stream (an SEI message): the preset's, not medium's.
  std::ifstream bytes(file, std::ios::binary);
  const std::string content((std::istreambuf_iterator<char>(bytes)), {});
  EXPECT_NE(content.find("x264 - core"), std::string::npos);
  EXPECT_NE(content.find("subme=1 "), std::string::npos);  // superfast; medium is subme=7
  EXPECT_NE(content.find("trellis=0"), std::string::npos);
  fs::remove_all(file.parent_path());
}

TEST(Sinks, PngFolderNumbersFrames) {
  const fs::path folder = Scratch("pngs");
  auto sink = OpenSink(folder.string() + "/", {160, 120}, 30);
  sink->Write(Frame(0));
  sink->Write(Frame(1));
  EXPECT_TRUE(fs::exists(folder / "000000.png"));
  EXPECT_TRUE(fs::exists(folder / "000001.png"));
  EXPECT_THROW(sink->Write(cv::Mat(10, 10, CV_8UC3)), VideoError);
  fs::remove_all(folder.parent_path());
}

TEST(Sinks, WindowWithoutDisplaySaysSo) {
  if (HasDisplay()) GTEST_SKIP() << "a display is present";
  try {
    OpenSink("window", {160, 120}, 30);
    FAIL() << "expected VideoError";
  } catch (const VideoError& e) {
    EXPECT_NE(std::string(e.what()).find("DISPLAY"), std::string::npos) << e.what();
  }
}

TEST(Sinks, RejectsUnknownTargets) {
  EXPECT_THROW(OpenSink("out.gif", {160, 120}, 30), VideoError);
  EXPECT_THROW(OpenSink("/nonexistent-folder/x.mp4", {160, 120}, 30), VideoError);
  EXPECT_THROW(OpenSink("", {160, 120}, 30), VideoError);
}

}  // namespace
}  // namespace arview::video
