#include "base/image_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/error.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("arview_image_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(WriteImageAtomically, WritesAPngThatReadsBackExactly) {
  const fs::path dir = TempDir("png");
  cv::Mat image(4, 5, CV_8UC3);
  cv::randu(image, 0, 255);
  WriteImageAtomically(dir / "a.png", image);
  const cv::Mat back = cv::imread((dir / "a.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), {}), 1);
  fs::remove_all(dir);
}

TEST(WriteImageAtomically, AnUnknownExtensionOrAnEmptyImageThrowsNamingTheFile) {
  const fs::path dir = TempDir("bad");
  cv::Mat image(2, 2, CV_8UC1, cv::Scalar(7));
  for (const fs::path& file : {dir / "a.nosuchformat", dir / "noextension"}) {
    try {
      WriteImageAtomically(file, image);
      FAIL() << "expected an error for " << file;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(WriteImageAtomically(dir / "empty.png", cv::Mat()), Error);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), {}), 0);
  fs::remove_all(dir);
}


std::string Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void Write(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// Returns the message of the Error ReadImageFile throws, and what was printed on stderr
// meanwhile (libpng prints its own "libpng error: ..." line unless the check comes first).
std::pair<std::string, std::string> ReadFailure(const fs::path& file) {
  std::string message;
  ::testing::internal::CaptureStderr();
  try {
    (void)ReadImageFile(file, cv::IMREAD_COLOR);
  } catch (const Error& e) {
    message = e.what();
  }
  return {message, ::testing::internal::GetCapturedStderr()};
}

TEST(ReadImageFile, ReadsWhatImreadReads) {
  const fs::path dir = TempDir("read");
  cv::Mat image(6, 7, CV_8UC3);
  cv::randu(image, 0, 255);
  cv::imwrite((dir / "a.png").string(), image);
  EXPECT_EQ(cv::norm(ReadImageFile(dir / "a.png", cv::IMREAD_COLOR), image, cv::NORM_INF), 0);
  fs::remove_all(dir);
}

// Issue 17: a truncated PNG frame printed libpng's own line before ours.
TEST(ReadImageFile, ATruncatedPngIsOneErrorNamingTheFileAndLibpngSaysNothing) {
  const fs::path dir = TempDir("truncated");
  cv::Mat image(64, 64, CV_8UC3);
  cv::randu(image, 0, 255);
  cv::imwrite((dir / "whole.png").string(), image);
  const std::string whole = Bytes(dir / "whole.png");
  for (size_t keep : {size_t{0}, size_t{7}, size_t{30}, whole.size() / 2, whole.size() - 1}) {
    const fs::path cut = dir / ("cut" + std::to_string(keep) + ".png");
    Write(cut, whole.substr(0, keep));
    const auto [message, printed] = ReadFailure(cut);
    EXPECT_EQ(message.rfind(cut.string() + ": ", 0), 0u) << keep << ": " << message;
    EXPECT_EQ(printed, "") << keep;
  }
  fs::remove_all(dir);
}

// Issue 17: a 65535x65535 PNG header printed OpenCV's internal assertion text.
TEST(ReadImageFile, AHugeOrZeroPngHeaderIsRefusedBeforeDecoding) {
  const fs::path dir = TempDir("huge");
  cv::Mat image(8, 8, CV_8UC1, cv::Scalar(3));
  cv::imwrite((dir / "small.png").string(), image);
  const std::string small = Bytes(dir / "small.png");
  for (const char* size : {"\xff\xff", "\x00\x00"}) {
    std::string mutated = small;
    // IHDR's width and height: big-endian 32-bit at bytes 16 and 20.
    mutated.replace(18, 2, size, 2);
    mutated.replace(22, 2, size, 2);
    const fs::path file = dir / "mutated.png";
    Write(file, mutated);
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string() + ": the image header says ", 0), 0u) << message;
    EXPECT_EQ(printed, "");
  }
  fs::remove_all(dir);
}

TEST(ReadImageFile, NotAnImageADirectoryAndAnEmptyFileNameTheFile) {
  const fs::path dir = TempDir("notimage");
  Write(dir / "text.png", "hello, not a picture");
  Write(dir / "empty.png", "");
  for (const fs::path& file : {dir / "text.png", dir / "empty.png", dir / "missing.png", dir}) {
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string(), 0), 0u) << message;
    EXPECT_EQ(printed, "") << file;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
