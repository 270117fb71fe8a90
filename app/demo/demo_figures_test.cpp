#include "app/demo/demo_figures.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <filesystem>

#include "video/sinks.h"

namespace arview::app {
namespace {

// A camera at the origin looking along +y of a z-up world (x right, z up in the picture).
calib::Pose LookingAlongY(const Eigen::Vector3d& centre) {
  Eigen::Matrix3d r_wc;
  r_wc << Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY();
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), centre);
}

CharacterMarkers StandingAt(const Eigen::Vector3d& feet, double height) {
  CharacterMarkers m;
  m.root = feet + Eigen::Vector3d(0, 0, 0.55 * height);
  m.head = feet + Eigen::Vector3d(0, 0, 0.92 * height);
  for (int corner = 0; corner < 8; ++corner)
    m.extent.push_back(feet + Eigen::Vector3d(corner & 1 ? 0.2 : -0.2, corner & 2 ? 0.1 : -0.1, corner & 4 ? height : 0));
  return m;
}

TEST(DemoFigures, InViewNeedsHeadAndHipsInThePictureAndATrackedFrame) {
  const calib::Camera camera = calib::Camera::Pinhole(640, 480, 525, 525, 319.5, 239.5);
  const CharacterMarkers figure = StandingAt({0, 4, 0}, 1.7);
  std::vector<std::optional<calib::Pose>> poses = {
      LookingAlongY({0, 0, 0.85}),    // whole figure in view: 525 · 1.7 / 4 = 223 px of 480
      LookingAlongY({3, 0, 0.85}),    // off to the side: out of view
      std::nullopt,                   // tracking lost: nothing drawn
      LookingAlongY({0, 2.2, 1.3}),   // 1.8 m away, higher: head and hips in, the feet below the picture
  };
  const InViewSummary s = MeasureInView(camera, poses, figure);
  EXPECT_EQ(s.frames, 4u);
  EXPECT_EQ(s.in_view, 2u);
  EXPECT_EQ(s.per_frame, (std::vector<bool>{true, false, false, true}));
  // Box depth ±0.1 m around 4 m: the near face gives the extent, 525 · 1.7 / 3.9 px.
  EXPECT_NEAR(s.height_fraction[0], 525 * 1.7 / 3.9 / 480, 0.01);
  EXPECT_DOUBLE_EQ(s.height_fraction[2], 0.0);
  // The box's top (0.4 m above the camera) at the near face, 1.7 m away; its bottom clipped.
  EXPECT_NEAR(s.height_fraction[3], (480 - (239.5 - 525 * 0.4 / 1.7)) / 480, 1e-6);
  EXPECT_EQ(s.at_least_a_fifth, 2u);
  EXPECT_NEAR(s.min_height_fraction, s.height_fraction[0], 1e-12);
}

TEST(DemoFigures, ContactSheetSpreadsFramesOverTheVideo) {
  const std::filesystem::path video = std::filesystem::temp_directory_path() / "arview_contact_sheet_test.avi";
  {
    cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, {160, 120});
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 23; ++i) writer.write(cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(10 * i)));
  }
  const cv::Mat sheet = ContactSheet(video, 12, 4, 80);
  EXPECT_EQ(sheet.cols, 4 * 80);
  EXPECT_EQ(sheet.rows, 3 * 60);
  // Tile k shows frame round(k · 22 / 11) = 2k: grey 20k (JPEG keeps a flat grey within a level or two).
  for (int k = 0; k < 12; ++k) {
    const cv::Vec3b centre = sheet.at<cv::Vec3b>((k / 4) * 60 + 20, (k % 4) * 80 + 40);
    EXPECT_NEAR(centre[0], 20 * k, 3) << "tile " << k;
  }
  std::filesystem::remove(video);
  EXPECT_THROW(ContactSheet(video, 12, 4, 80), std::runtime_error);
}

// `arview demo --out <folder>` writes PNG frames (video/sinks.h); the sheet reads them back.
TEST(DemoFigures, ContactSheetReadsAFolderOfPngFrames) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "arview_contact_sheet_png_test";
  std::filesystem::remove_all(folder);
  {
    const auto sink = video::OpenSink(folder.string(), {160, 120}, 30);
    for (int i = 0; i < 23; ++i) sink->Write(cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(10 * i)));
    sink->Close();
  }
  const cv::Mat sheet = ContactSheet(folder, 12, 4, 80);
  ASSERT_EQ(sheet.cols, 4 * 80);
  for (int k = 0; k < 12; ++k) {
    const cv::Vec3b centre = sheet.at<cv::Vec3b>((k / 4) * 60 + 20, (k % 4) * 80 + 40);
    EXPECT_EQ(centre[0], 20 * k) << "tile " << k;  // PNG: exact
  }
  std::filesystem::remove_all(folder);
}

// A frame to include takes the place of the spread frame nearest it, and only that one.
TEST(DemoFigures, ContactSheetIncludesTheFrameAskedForInPlaceOfTheNearest) {
  const std::filesystem::path video = std::filesystem::temp_directory_path() / "arview_contact_sheet_include_test.avi";
  {
    cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, {160, 120});
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 23; ++i) writer.write(cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(10 * i)));
  }
  // Spread: frames 0, 2, 4, ..., 22; frame 9 is nearest 8 (tile 4) and 10 (tile 5): the first.
  const cv::Mat sheet = ContactSheet(video, 12, 4, 80, 9);
  for (int k = 0; k < 12; ++k) {
    const cv::Vec3b centre = sheet.at<cv::Vec3b>((k / 4) * 60 + 20, (k % 4) * 80 + 40);
    EXPECT_NEAR(centre[0], k == 4 ? 90 : 20 * k, 3) << "tile " << k;
  }
  // A frame the video does not have changes nothing.
  const cv::Mat unchanged = ContactSheet(video, 12, 4, 80, 99);
  EXPECT_EQ(cv::norm(unchanged, ContactSheet(video, 12, 4, 80), cv::NORM_INF), 0);
  std::filesystem::remove(video);
}

TEST(DemoFigures, TheCloseUpIsARowBelowTheSheetCroppedAboutItsCentre) {
  const cv::Mat sheet(3 * 60, 4 * 80, CV_8UC3, cv::Scalar::all(40));
  cv::Mat close_up(120, 160, CV_8UC3, cv::Scalar::all(0));
  close_up(cv::Rect(40, 30, 80, 60)).setTo(cv::Scalar(200, 100, 50));  // the centre tile's area
  const cv::Mat out = WithCloseUp(sheet, close_up, 80, 60, {"the face from 0.6 m"});
  ASSERT_EQ(out.cols, sheet.cols);
  ASSERT_EQ(out.rows, sheet.rows + 60);
  EXPECT_EQ(out.at<cv::Vec3b>(10, 10), cv::Vec3b(40, 40, 40)) << "the sheet is kept";
  EXPECT_EQ(out.at<cv::Vec3b>(180, 0), cv::Vec3b(200, 100, 50)) << "the crop's corner is the close-up's centre tile";
  EXPECT_EQ(out.at<cv::Vec3b>(239, 79), cv::Vec3b(200, 100, 50));
  EXPECT_GT(cv::countNonZero(out(cv::Rect(80, 180, 240, 60)).reshape(1)), 0) << "the text beside it";
  EXPECT_THROW(WithCloseUp(sheet, close_up(cv::Rect(0, 0, 60, 60)), 80, 60, {}), std::invalid_argument);
}

}  // namespace
}  // namespace arview::app
