#include "calib/camera.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <opencv2/calib3d.hpp>

#include <filesystem>
#include <fstream>
#include <random>

namespace arview::calib {
namespace {

Camera DistortedCamera() {
  Camera c = Camera::Pinhole(640, 480, 535.9, 536.1, 342.3, 235.6);
  c.dist = {-0.27, 0.05, 0.0012, -0.0004, 0.12};
  return c;
}

TEST(Camera, ProjectMatchesOpenCvProjectPoints) {
  const Camera c = DistortedCamera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<cv::Point3d> pts;
  for (int i = 0; i < 200; ++i) pts.emplace_back(u(rng), u(rng), 1.0 + std::abs(u(rng)) * 3);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.K(), c.DistCoeffs(), expected);
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d p = c.Project({pts[i].x, pts[i].y, pts[i].z});
    EXPECT_NEAR(p.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(p.y(), expected[i].y, 1e-9);
  }
}

TEST(Camera, UnprojectInvertsProjectAcrossTheImage) {
  const Camera c = DistortedCamera();
  for (int y = 0; y < c.height; y += 40) {
    for (int x = 0; x < c.width; x += 40) {
      const Eigen::Vector3d bearing = c.Unproject({x, y});
      EXPECT_NEAR(bearing.norm(), 1.0, 1e-12);
      const Eigen::Vector2d back = c.Project(bearing);
      EXPECT_NEAR(back.x(), x, 1e-8);
      EXPECT_NEAR(back.y(), y, 1e-8);
    }
  }
}

TEST(Camera, UndistortPixelAgreesWithOpenCv) {
  const Camera c = DistortedCamera();
  std::vector<cv::Point2d> in{{100, 80}, {320, 240}, {600, 450}, {20, 400}};
  std::vector<cv::Point2d> out;
  cv::undistortPoints(in, out, c.K(), c.DistCoeffs(), cv::noArray(), c.K(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
  for (size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector2d u = c.UndistortPixel({in[i].x, in[i].y});
    EXPECT_NEAR(u.x(), out[i].x, 1e-4);
    EXPECT_NEAR(u.y(), out[i].y, 1e-4);
  }
}

// A folder of this test process's own: ctest runs each test as its own process, two at a time,
// and two tests writing one /tmp file raced (one removed it while the other loaded it).
std::filesystem::path ProcessTempDir() {
  const auto dir = std::filesystem::temp_directory_path() / ("arview_camera_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(Camera, SaveLoadRoundTrip) {
  const Camera c = DistortedCamera();
  const auto path = ProcessTempDir() / "arview_camera_roundtrip.yaml";
  SaveCamera(c, path);
  const Camera d = LoadCamera(path);
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.height, 480);
  EXPECT_DOUBLE_EQ(d.fx, c.fx);
  EXPECT_DOUBLE_EQ(d.cy, c.cy);
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(d.dist[i], c.dist[i]);
  EXPECT_FALSE(d.focus.has_value());  // not known unless said
  Camera focused = c;
  focused.focus = 250;
  SaveCamera(focused, path);
  EXPECT_EQ(LoadCamera(path).focus, std::optional<std::int64_t>(250));
  std::filesystem::remove(path);
  std::error_code ignored;
  std::filesystem::remove(path.parent_path(), ignored);
}

void WriteFile(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string LoadError(const std::string& yaml) {
  const auto path = ProcessTempDir() / "arview_camera_bad.yaml";
  WriteFile(path, yaml);
  try {
    LoadCamera(path);
  } catch (const CameraError& e) {
    std::filesystem::remove(path);
    std::error_code ignored;
    std::filesystem::remove(path.parent_path(), ignored);  // the folder, once empty
    return e.what();
  }
  std::filesystem::remove(path);
  std::error_code ignored;
  std::filesystem::remove(path.parent_path(), ignored);
  return "";
}

const char* kGood =
    "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
    "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n";

TEST(Camera, LoadRejectsBadFilesNamingTheField) {
  EXPECT_NE(LoadError(std::string(kGood) + "focus_absolute: 2.5\n").find("line 10: focus_absolute '2.5' must be a whole number"),
            std::string::npos);
  EXPECT_EQ(LoadError(kGood), "");

  EXPECT_NE(LoadError("not yaml at all {{{").find("arview_camera_bad.yaml"), std::string::npos);
  std::string no_width = kGood;
  no_width.replace(no_width.find("image_width: 640"), 16, "image_wide: 640");
  EXPECT_NE(LoadError(no_width).find("image_width is missing"), std::string::npos);
  std::string neg_f = kGood;
  neg_f.replace(neg_f.find("500., 0., 320."), 4, "-500");
  EXPECT_NE(LoadError(neg_f).find("fx must be a positive"), std::string::npos);
  std::string outside = kGood;
  outside.replace(outside.find("320."), 4, "900.");
  EXPECT_NE(LoadError(outside).find("principal point cx"), std::string::npos);
  std::string zero_h = kGood;
  zero_h.replace(zero_h.find("image_height: 480"), 17, "image_height: 0  ");
  EXPECT_NE(LoadError(zero_h).find("image_height must be positive"), std::string::npos);
  EXPECT_THROW(LoadCamera("/nonexistent/camera.yaml"), CameraError);
}

// Issue 56: a camera estimated without a calibration keeps saying so through its file.
TEST(Camera, AnEstimatedCameraIsMarkedUncalibratedAndKeepsItsSource) {
  const Camera guessed = EstimatedCamera(1080, 1920, GuessedFocal(1080, 1920), "a guess: 0.6 x the diagonal");
  EXPECT_FALSE(guessed.calibrated);
  EXPECT_NEAR(guessed.fx, 0.6 * 2202.9, 0.1);
  EXPECT_DOUBLE_EQ(guessed.cx, 539.5);
  EXPECT_DOUBLE_EQ(guessed.cy, 959.5);
  const auto path = ProcessTempDir() / "arview_camera_estimated.yaml";
  SaveCamera(guessed, path);
  const Camera loaded = LoadCamera(path);
  EXPECT_FALSE(loaded.calibrated);
  EXPECT_EQ(loaded.intrinsics_source, "a guess: 0.6 x the diagonal");
  SaveCamera(DistortedCamera(), path);  // a calibration writes neither key and loads as calibrated
  EXPECT_TRUE(LoadCamera(path).calibrated);
  EXPECT_TRUE(LoadCamera(path).intrinsics_source.empty());
  std::filesystem::remove(path);
  std::error_code ignored;
  std::filesystem::remove(path.parent_path(), ignored);
  EXPECT_NEAR(FocalFromHorizontalFov(640, 90, "--fov"), 320, 1e-9);
  EXPECT_THROW(FocalFromHorizontalFov(640, 0, "--fov"), CameraError);
  EXPECT_NE(LoadError(std::string(kGood) + "calibrated: 2\n").find("calibrated must be 0 or 1"), std::string::npos);
}

// Issue 17's fuzzer reproducers: each was a crash, a huge allocation or a silently wrong camera.
TEST(Camera, MatrixHeadersThatMadeOpenCvAllocateGigabytesAreRefused) {
  for (const std::string rows : {"+", "\xd9\xa3" /* ARABIC-INDIC DIGIT THREE */, "99999999", "0", "-3"}) {
    std::string bad = kGood;
    bad.replace(bad.find("rows: 3"), 7, "rows: " + rows);
    const std::string m = LoadError(bad);
    EXPECT_NE(m.find("arview_camera_bad.yaml: line 6: matrix rows"), std::string::npos) << rows << ": " << m;
  }
}

// The 10-minute fuzz_camera campaign's finding (2026-12-02): this 21-byte file sent OpenCV's
// reader into an endless loop; it is refused before it.
TEST(Camera, TheCampaignsEndlessLoopFileIsRefusedBeforeTheParser) {
  const std::string m = LoadError("%YAML:1.\n----\xff\n0\n\xf4");
  EXPECT_NE(m.find("arview_camera_bad.yaml: line 2: '----"), std::string::npos) << m;
  EXPECT_NE(m.find("is not the document marker '---'"), std::string::npos) << m;
}

TEST(Camera, DeepNestingIsRefusedBeforeTheParser) {
  // 50,000 levels overflowed the stack of OpenCV's YAML parser (SIGSEGV).
  const std::string deep = std::string(kGood) + "x: " + std::string(50000, '[') + std::string(50000, ']') + "\n";
  EXPECT_NE(LoadError(deep).find("nested"), std::string::npos);
}

TEST(Camera, SkewAndTheOtherEntriesOfKAreRefusedNotIgnored) {
  std::string skew = kGood;
  skew.replace(skew.find("500., 0., 320."), 14, "500., 2., 320.");
  EXPECT_NE(LoadError(skew).find("skew"), std::string::npos);
  std::string last_row = kGood;
  last_row.replace(last_row.find("0., 0., 1."), 10, "0., 0., 2.");
  EXPECT_NE(LoadError(last_row).find("last row must be 0 0 1"), std::string::npos);
  std::string k10 = kGood;
  k10.replace(k10.find("0., 500., 240."), 14, "7., 500., 240.");
  EXPECT_NE(LoadError(k10).find("K[1][0]"), std::string::npos);
}

TEST(Camera, IntegerMatrixTypesThatSaturatedAreRefused) {
  std::string u8 = kGood;
  u8.replace(u8.find("dt: d"), 5, "dt: u");
  EXPECT_NE(LoadError(u8).find("dt: u is not a floating-point type"), std::string::npos);
}

TEST(Camera, AKeyGivenTwiceIsRefusedWithItsLine) {
  const std::string twice = std::string(kGood) + "image_width: 320\n";
  EXPECT_NE(LoadError(twice).find("line 10: key 'image_width' given twice (first on line 3)"), std::string::npos)
      << LoadError(twice);
}

TEST(Camera, UnknownKeysAreRefusedAndOpenCvsInformationalOnesAccepted) {
  EXPECT_NE(LoadError(std::string(kGood) + "skew: 0.5\n").find("unknown key 'skew'"), std::string::npos);
  EXPECT_EQ(LoadError(std::string(kGood) + "avg_reprojection_error: 0.39\nnframes: 13\n"), "");
  EXPECT_NE(LoadError(std::string(kGood) + "fisheye_model: 1\n").find("fisheye"), std::string::npos);
}

TEST(Camera, HugeFocalLengthsAndSizesAreRefused) {
  std::string huge = kGood;
  huge.replace(huge.find("500., 0., 320."), 4, "1e308");
  EXPECT_NE(LoadError(huge).find("fx must be a positive number up to"), std::string::npos);
}

// Issue 41: a camera_matrix without its `dt` line made OpenCV throw std::length_error, and the
// user saw "arview: basic_string::_M_create". Each of the matrix's keys missing is named.
TEST(Camera, AMatrixWithoutOneOfItsKeysIsRefusedNamingTheFileAndTheKey) {
  for (const std::string key : {"rows", "cols", "dt", "data"}) {
    std::string bad = kGood;
    const size_t line = bad.find("   " + key + ":");
    bad.erase(line, bad.find('\n', line) + 1 - line);
    const std::string m = LoadError(bad);
    EXPECT_NE(m.find("arview_camera_bad.yaml: field camera_matrix: the matrix has no '" + key + "' key"),
              std::string::npos)
        << key << ": " << m;
    EXPECT_EQ(m.find("basic_string"), std::string::npos) << m;
  }
}

// Issue 57: OpenCV's reader wrapped a focus position beyond 32 bits (2147483648 read as
// -2147483648, 1e20 as -1), a wrong focus taken silently; the map file's reader refuses them.
TEST(Camera, AFocusPositionBeyond32BitsIsRefusedNotWrapped) {
  for (const std::string value : {"2147483648", "-2147483649", "1e20", "99999999999999999999"}) {
    const std::string m = LoadError(std::string(kGood) + "focus_absolute: " + value + "\n");
    EXPECT_NE(m.find("arview_camera_bad.yaml: line 10: focus_absolute '" + value +
                     "' must be a whole number from -2147483648 to 2147483647"),
              std::string::npos)
        << value << ": " << m;
  }
  for (const std::int64_t held : {std::int64_t{2147483647}, std::int64_t{-2147483648}, std::int64_t{0}}) {
    const auto path = ProcessTempDir() / "arview_camera_focus.yaml";
    WriteFile(path, std::string(kGood) + "focus_absolute: " + std::to_string(held) + "  # the lens\n");
    EXPECT_EQ(LoadCamera(path).focus, std::optional<std::int64_t>(held));
    std::filesystem::remove(path);
  }
}

// Issue 57: the distortion matrix's `dt` line damaged to an empty key ("   : d") reached the user
// as "cam.yaml: basic_string::_M_create"; the line and the field are named.
TEST(Camera, AnEmptyKeyIsRefusedNamingItsLineAndField) {
  std::string damaged = std::string(kGood) +
                        "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   : d\n"
                        "   data: [ 0.1, -0.2, 0., 0., 0. ]\n";
  std::string m = LoadError(damaged);
  EXPECT_NE(m.find("arview_camera_bad.yaml: line 13: a key of distortion_coefficients is empty (before ': d'"),
            std::string::npos)
      << m;
  EXPECT_EQ(m.find("basic_string"), std::string::npos) << m;
  m = LoadError(std::string(kGood) + ": 3\n");
  EXPECT_NE(m.find("line 10: a key is empty"), std::string::npos) << m;
}

TEST(Camera, DevicesFifosAndDirectoriesAreNotReadAsCameraFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("arview_camera_special_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink("/dev/zero", dir / "zero.yaml");
  ASSERT_EQ(::mkfifo((dir / "fifo.yaml").c_str(), 0600), 0);
  for (const char* name : {"zero.yaml", "fifo.yaml"}) {
    try {
      LoadCamera(dir / name);
      ADD_FAILURE() << name << " loaded";
    } catch (const CameraError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(LoadCamera(dir), CameraError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace arview::calib
