#include "calib/calibration.h"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "tests/support/test_data.h"

namespace arview::calib {
namespace {

namespace fs = std::filesystem;
const char* kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("arview_calib_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(Calibration, OpenCvSamplePhotosMatchOpenCvsReference) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvData) / "left01.jpg", "Debian package opencv-doc");
  const auto files = ExpandImageGlob(std::string(kOpenCvData) + "/left[0-9]*.jpg");
  ASSERT_EQ(files.size(), 13u);
  const CalibrationResult r = Calibrate(files, CalibrationOptions{});
  EXPECT_LE(r.rms, 0.45);
  EXPECT_NEAR(r.camera.fx, 535.9, 5.359);
  EXPECT_NEAR(r.camera.fy, 535.9, 5.359);
  EXPECT_NEAR(r.camera.cx, 342.3, 3.0);
  EXPECT_NEAR(r.camera.cy, 235.6, 3.0);
  EXPECT_GE(r.views_used, 10);
  EXPECT_EQ(r.views_used + r.views_rejected, 13);
  EXPECT_GT(r.coverage, 0.3);
  const cv::Mat report = DrawCalibrationReport(r);
  EXPECT_EQ(report.cols, 2 * r.camera.width);
}

TEST(Calibration, GlobMatchingNothingIsAnError) {
  EXPECT_NE(ErrorOf([] { ExpandImageGlob("/nonexistent/folder/*.jpg"); }).find("matches no file"), std::string::npos);
}

TEST(Calibration, ImagesWithoutBoardAreAnError) {
  const fs::path d = TempDir("noboard");
  std::vector<std::string> files;
  for (int i = 0; i < 4; ++i) {
    const std::string f = (d / ("blank" + std::to_string(i) + ".png")).string();
    cv::imwrite(f, cv::Mat(480, 640, CV_8UC1, cv::Scalar(60 * i)));
    files.push_back(f);
  }
  const std::string e = ErrorOf([&] { Calibrate(files, CalibrationOptions{}); });
  EXPECT_NE(e.find("no board found"), std::string::npos) << e;
  fs::remove_all(d);
}

TEST(Calibration, ImagesOfDifferentSizesAreAnError) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvData) / "left01.jpg", "Debian package opencv-doc");
  const fs::path d = TempDir("sizes");
  const cv::Mat a = cv::imread(std::string(kOpenCvData) + "/left01.jpg");
  cv::Mat b;
  cv::resize(a, b, {320, 240});
  cv::imwrite((d / "a.png").string(), a);
  cv::imwrite((d / "b.png").string(), b);
  const std::string e = ErrorOf([&] { Calibrate({(d / "a.png").string(), (d / "b.png").string()}, CalibrationOptions{}); });
  EXPECT_NE(e.find("b.png: image is 320x240"), std::string::npos) << e;
  fs::remove_all(d);
}

TEST(Calibration, FewerThanThreeUsableViewsIsAnError) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvData) / "left01.jpg", "Debian package opencv-doc");
  const fs::path d = TempDir("few");
  cv::imwrite((d / "blank.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  const std::string e = ErrorOf([&] {
    Calibrate({std::string(kOpenCvData) + "/left01.jpg", std::string(kOpenCvData) + "/left03.jpg",
               (d / "blank.png").string()},
              CalibrationOptions{});
  });
  EXPECT_NE(e.find("only 2 usable view(s) of 3 image(s)"), std::string::npos) << e;
  fs::remove_all(d);
}

TEST(Calibration, UnreadableImageIsNamed) {
  const std::string e = ErrorOf([] { Calibrate({"/nonexistent/x.png"}, CalibrationOptions{}); });
  EXPECT_NE(e.find("/nonexistent/x.png: does not exist"), std::string::npos) << e;
}

// Issue 17: a photo cut short (a copy interrupted) made libjpeg print "Premature end of JPEG
// file" and the calibration went on with the photo's missing part grey.
TEST(Calibration, ATruncatedPhotoIsOneErrorNamingItAndLibjpegSaysNothing) {
  const fs::path photo = fs::path(kOpenCvData) / "left01.jpg";
  ARVIEW_REQUIRE_DATA_PATH(photo, "Debian package opencv-doc");
  const fs::path d = TempDir("truncated");
  std::ifstream in(photo, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const fs::path cut = d / "left01.jpg";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  std::vector<std::string> paths = {cut.string()};
  for (const char* name : {"left02.jpg", "left03.jpg"}) paths.push_back((fs::path(kOpenCvData) / name).string());
  ::testing::internal::CaptureStderr();
  const std::string e = ErrorOf([&] { Calibrate(paths, CalibrationOptions{}); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(e.rfind(cut.string() + ": the JPEG is cut short", 0), 0u) << e;
  fs::remove_all(d);
}

TEST(Calibration, UnwritableOutputIsAnError) {
  const Camera c = Camera::Pinhole(640, 480, 500, 500, 320, 240);
  EXPECT_NE(ErrorOf([&] { SaveCamera(c, "/nonexistent/folder/camera.yaml"); }).find("/nonexistent/folder/camera.yaml"),
            std::string::npos);
}

// Synthetic ChArUco views: the printed board seen by a known pinhole camera from several poses.
TEST(Calibration, CharucoRecoversAKnownCamera) {
  CalibrationOptions o;
  o.kind = BoardKind::kCharuco;
  o.board = {7, 5};
  o.square_size = 0.04;
  const int pps = 100;
  const cv::Mat board = DrawCharucoBoard(o, pps);  // margin pps/2 around the squares
  const double metres_per_pixel = o.square_size / pps;
  const cv::Matx33d board_to_plane(metres_per_pixel, 0, -pps / 2 * metres_per_pixel, 0, metres_per_pixel,
                                   -pps / 2 * metres_per_pixel, 0, 0, 1);
  const cv::Matx33d K(600, 0, 322, 0, 600, 241, 0, 0, 1);
  const fs::path d = TempDir("charuco");
  std::vector<std::string> files;
  const double angles[][3] = {{0.3, 0.1, 0.0}, {-0.3, 0.2, 0.1}, {0.1, -0.35, -0.1}, {-0.2, -0.25, 0.2},
                              {0.35, 0.3, 0.0}, {0.0, 0.4, 0.3}, {-0.4, 0.0, -0.2}};
  for (size_t i = 0; i < std::size(angles); ++i) {
    cv::Matx33d R;
    cv::Rodrigues(cv::Vec3d(angles[i][0], angles[i][1], angles[i][2]), R);
    const cv::Vec3d centre(0.14, 0.10, 0);  // middle of the 7x5 board of 4 cm squares
    const cv::Vec3d t = -(R * centre) + cv::Vec3d(0, 0, 0.45);
    const cv::Matx33d plane_to_camera(R(0, 0), R(0, 1), t[0], R(1, 0), R(1, 1), t[1], R(2, 0), R(2, 1), t[2]);
    const cv::Matx33d H = K * plane_to_camera * board_to_plane;
    cv::Mat view;
    cv::warpPerspective(board, view, cv::Mat(H), {640, 480}, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
    cv::GaussianBlur(view, view, {3, 3}, 0.6);
    files.push_back((d / ("view" + std::to_string(i) + ".png")).string());
    cv::imwrite(files.back(), view);
  }
  const CalibrationResult r = Calibrate(files, o);
  EXPECT_GE(r.views_used, 6);
  EXPECT_LT(r.rms, 0.5);
  EXPECT_NEAR(r.camera.fx, 600, 6);
  EXPECT_NEAR(r.camera.fy, 600, 6);
  EXPECT_NEAR(r.camera.cx, 322, 4);
  EXPECT_NEAR(r.camera.cy, 241, 4);
  fs::remove_all(d);
}

}  // namespace
}  // namespace arview::calib
