// The HMD presentation (render/hmd.h): a straight line of the view lands on the curve the
// profile's pre-distortion predicts, within 0.5 px; identical views give identical halves under
// centred lenses; a bad profile is one message naming the file and the field.

#include "render/hmd.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <opencv2/imgproc.hpp>

#include "render/offscreen.h"
#include "tests/support/test_data.h"

namespace arview::render {
namespace {

namespace fs = std::filesystem;

HmdProfile Cardboard() {
  HmdProfile p;
  p.name = "test";
  p.panel = {1280, 720};
  p.eye_fov_deg = 90;
  p.lens_centre = {0.5, 0.5};
  p.k1 = 0.34, p.k2 = 0.55;
  return p;
}

// A wide view (f = 300: 94 deg across), so that the line reaches far from the lens centre.
const calib::Camera kView = calib::Camera::Pinhole(640, 480, 300, 300, 320, 240);

// The x of the eye-0 panel pixel in row y that samples the view's column x0 (bisection: the
// sampled x grows with the panel x along a row).
double PanelXOfViewColumn(const HmdPresenter& hmd, double x0, double y) {
  double lo = 0, hi = hmd.panel().width / 2.0 - 1;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (hmd.SourceOf(0, {mid, y}).x() < x0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Hmd, AStraightLineLandsOnTheProfilesCurveWithinHalfAPixel) {
  const HmdPresenter hmd(Cardboard(), kView);
  cv::Mat view(kView.Size(), CV_8UC3, cv::Scalar::all(0));
  const int x0 = 520;  // a vertical line of the view, right of its centre
  view.col(x0).setTo(cv::Scalar::all(255));
  const cv::Mat panel = hmd.Present(view, view);
  ASSERT_EQ(panel.size(), cv::Size(1280, 720));
  const cv::Mat left = panel(cv::Rect(0, 0, 640, 720));
  cv::Mat gray;
  cv::cvtColor(left, gray, cv::COLOR_BGR2GRAY);
  int rows = 0;
  double worst = 0, leftmost = 1e9, rightmost = -1e9;
  for (int y = 0; y < gray.rows; y += 4) {
    // The line's centre in this row: the intensity centroid of the pixels it lit.
    double sum = 0, weighted = 0;
    for (int x = 0; x < gray.cols; ++x) {
      const double v = gray.at<uchar>(y, x);
      sum += v, weighted += v * x;
    }
    if (sum < 200) continue;  // the line is outside the view in this row
    const double measured = weighted / sum;
    const double expected = PanelXOfViewColumn(hmd, x0, y);
    worst = std::max(worst, std::abs(measured - expected));
    leftmost = std::min(leftmost, measured), rightmost = std::max(rightmost, measured);
    ++rows;
  }
  EXPECT_GT(rows, 20);
  EXPECT_LE(worst, 0.5) << "px from the profile's curve";
  // The pre-distortion bends the line (barrel): not a straight column on the panel.
  EXPECT_GT(rightmost - leftmost, 5);
}

TEST(Hmd, TheLensCentreSamplesTheViewsCentreAndWithoutDistortionScalesByTheFocalRatio) {
  HmdProfile flat = Cardboard();
  flat.k1 = flat.k2 = 0;
  const HmdPresenter hmd(flat, kView);
  for (int eye = 0; eye < 2; ++eye) {
    const Eigen::Vector2d c = hmd.LensCentre(eye);
    EXPECT_NEAR((hmd.SourceOf(eye, c) - Eigen::Vector2d(320, 240)).norm(), 0, 1e-9);
    // 90 deg across 640 panel pixels: f = 320; the view's f = 300, so 10 panel px are 9.4 view px.
    EXPECT_NEAR(hmd.SourceOf(eye, c + Eigen::Vector2d(10, 0)).x() - 320, 10 * 300.0 / 320.0, 1e-9);
  }
}

TEST(Hmd, IdenticalViewsGiveIdenticalHalvesUnderCentredLenses) {
  const HmdPresenter hmd(Cardboard(), kView);
  cv::Mat view(kView.Size(), CV_8UC3);
  cv::randu(view, 0, 255);
  const cv::Mat panel = hmd.Present(view, view);
  EXPECT_EQ(cv::norm(panel(cv::Rect(0, 0, 640, 720)), panel(cv::Rect(640, 0, 640, 720)), cv::NORM_INF), 0);
}

TEST(Hmd, ABadProfileIsOneMessageNamingTheFileAndTheField) {
  const fs::path dir = fs::temp_directory_path() / ("arview_hmd_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto expect_error = [&](const std::string& text, const std::string& words) {
    const fs::path file = dir / "profile.yaml";
    std::ofstream(file) << text;
    try {
      LoadHmdProfile(file);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      EXPECT_NE(message.find(words), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  expect_error("panel: [2560, 1440]\n", "eye_fov_deg is missing");
  expect_error("panel: [2561, 1440]\neye_fov_deg: 90\n", "panel width must be even");
  expect_error("panel: [2560]\neye_fov_deg: 90\n", "panel must be a list of two numbers");
  expect_error("panel: [2560, 1440]\neye_fov_deg: 190\n", "eye_fov_deg");
  expect_error("panel: [2560, 1440]\neye_fov_deg: 90\ndistortion: [nan, 0]\n", "distortion[0]");
  expect_error("panel: [2560, 1440]\neye_fov_deg: 90\nlens: [0.5, 0.5]\n", "unknown key 'lens'");
  expect_error("panel: [2560, 1440]\npanel: [2560, 1440]\neye_fov_deg: 90\n", "appears twice");
  std::ofstream(dir / "good.yaml") << "name: x\npanel: [2560, 1440]\neye_fov_deg: 90\ndistortion: [0.34, 0.55]\n";
  const HmdProfile good = LoadHmdProfile(dir / "good.yaml");
  EXPECT_EQ(good.panel, cv::Size(2560, 1440));
  EXPECT_DOUBLE_EQ(good.k2, 0.55);
  fs::remove_all(dir);
}

TEST(Hmd, TheExampleProfileInTheDocsLoads) {
  const fs::path example = testing::SourceDir() / "docs/examples/hmd-cardboard.yaml";
  const HmdProfile p = LoadHmdProfile(example);
  EXPECT_EQ(p.panel, cv::Size(2560, 1440));
}

}  // namespace
}  // namespace arview::render
