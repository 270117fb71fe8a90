#include "base/image_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

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

}  // namespace
}  // namespace arview
