#include "calib/board_views.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/calib3d.hpp>

namespace arview::calib {
namespace {

const cv::Size kBoard{9, 6};
const cv::Size kImage{640, 480};

// The inner corners of a 9x6 board with squares of `square` px, its first corner at `origin`,
// seen straight on.
std::vector<cv::Point2f> FlatBoard(cv::Point2f origin, float square) {
  std::vector<cv::Point2f> corners;
  for (int row = 0; row < kBoard.height; ++row) {
    for (int column = 0; column < kBoard.width; ++column) corners.push_back(origin + cv::Point2f(column * square, row * square));
  }
  return corners;
}

// The board (25 mm squares) seen by a 600 px pinhole camera, turned `tilt_deg` about its rows'
// axis, its centre at `centre` (metres, camera coordinates).
std::vector<cv::Point2f> SeenBoard(cv::Point3d centre, double tilt_deg) {
  std::vector<cv::Point3f> object;
  for (int row = 0; row < kBoard.height; ++row) {
    for (int column = 0; column < kBoard.width; ++column) {
      object.emplace_back((column - 4) * 0.025f, (row - 2.5f) * 0.025f, 0.f);
    }
  }
  const cv::Vec3d rvec(0, tilt_deg * CV_PI / 180, 0), tvec(centre.x, centre.y, centre.z);
  const cv::Matx33d K(600, 0, 319.5, 0, 600, 239.5, 0, 0, 1);
  std::vector<cv::Point2f> corners;
  cv::projectPoints(object, rvec, tvec, K, cv::noArray(), corners);
  return corners;
}

TEST(PlaceBoard, BoardFacingTheCameraInTheMiddleIsCentredWithoutSkew) {
  // 8 x 40 by 5 x 40 px outline, its mean at the image's centre.
  const auto corners = FlatBoard({320 - 160, 240 - 100}, 40);
  const BoardPlacement p = PlaceBoard(corners, kBoard, kImage);
  EXPECT_NEAR(p.x, 0.5, 1e-6);
  EXPECT_NEAR(p.y, 0.5, 1e-6);
  EXPECT_NEAR(p.size, std::sqrt(320.0 * 200 / (640 * 480)), 1e-6);
  EXPECT_NEAR(p.skew, 0, 1e-6);
}

TEST(PlaceBoard, BoardAtTheLeftEdgeIsNearZeroAndATiltedBoardIsSkewed) {
  const BoardPlacement left = PlaceBoard(FlatBoard({0, 140}, 20), kBoard, kImage);
  EXPECT_LT(left.x, 0.05);
  const BoardPlacement tilted = PlaceBoard(SeenBoard({0.05, 0, 0.5}, 40), kBoard, kImage);
  EXPECT_GT(tilted.skew, 0.05);
  const BoardPlacement facing = PlaceBoard(SeenBoard({0.05, 0, 0.5}, 0), kBoard, kImage);
  EXPECT_LT(facing.skew, 0.01);
}

constexpr double kFrame = 1.0 / 30;

TEST(ViewSelector, TakesAStillBoardOnceAndNotAMovingOne) {
  ViewSelector selector(kBoard, kImage);
  const auto still = FlatBoard({100, 100}, 30);
  EXPECT_EQ(selector.Offer(still, 0), ViewSelector::Decision::kMoving);  // no motion known yet
  EXPECT_EQ(selector.Offer(still, kFrame), ViewSelector::Decision::kTaken);
  EXPECT_EQ(selector.Offer(still, 2 * kFrame), ViewSelector::Decision::kKnown);
  EXPECT_EQ(selector.taken().size(), 1u);
  // 3 px a frame at 30 fps across the image: moving, even where it would be a new view.
  ViewSelector moving(kBoard, kImage);
  for (int i = 0; i < 20; ++i) {
    EXPECT_NE(moving.Offer(FlatBoard({50.f + 3 * i, 100}, 30), i * kFrame), ViewSelector::Decision::kTaken) << i;
  }
  EXPECT_TRUE(moving.taken().empty());
}

TEST(ViewSelector, StillnessIsASpeedSoDroppedFramesDoNotMakeABoardMove) {
  ViewSelector selector(kBoard, kImage);
  selector.Offer(FlatBoard({100, 100}, 30), 0);
  // 2 px over four frame times (three dropped): 15 px/s, still.
  EXPECT_EQ(selector.Offer(FlatBoard({102, 100}, 30), 4 * kFrame), ViewSelector::Decision::kTaken);
  EXPECT_NEAR(selector.last_speed_px_per_s(), 15, 1e-3);
  // A frame with the same time as the one before says nothing of the speed.
  EXPECT_EQ(selector.Offer(FlatBoard({300, 100}, 30), 4 * kFrame), ViewSelector::Decision::kMoving);
  EXPECT_LT(selector.last_speed_px_per_s(), 0);
}

TEST(ViewSelector, ABoardLostInBetweenIsNotStillWhenSeenAgain) {
  ViewSelector selector(kBoard, kImage);
  const auto a = FlatBoard({100, 100}, 30);
  selector.Offer(a, 0);
  EXPECT_EQ(selector.Offer({}, kFrame), ViewSelector::Decision::kNoBoard);
  EXPECT_EQ(selector.Offer(a, 2 * kFrame), ViewSelector::Decision::kMoving);
  // A detection with too few corners is no board either.
  EXPECT_EQ(selector.Offer(std::vector<cv::Point2f>(a.begin(), a.begin() + 10), 3 * kFrame),
            ViewSelector::Decision::kNoBoard);
}

TEST(ViewSelector, SmallMotionBelowTheThresholdIsStill) {
  ViewSelectionOptions options;
  options.still_px_per_s = 30;
  ViewSelector selector(kBoard, kImage, options);
  selector.Offer(FlatBoard({100, 100}, 30), 0);
  EXPECT_EQ(selector.Offer(FlatBoard({100.6f, 100}, 30), kFrame), ViewSelector::Decision::kTaken);
  EXPECT_NEAR(selector.last_speed_px_per_s(), 18, 1e-2);
  selector.Offer(FlatBoard({300, 200}, 30), 2 * kFrame);
  EXPECT_EQ(selector.Offer(FlatBoard({301.5f, 200}, 30), 3 * kFrame), ViewSelector::Decision::kMoving);
}

// Holds each board still for two frames, as a person pauses.
void Show(ViewSelector& selector, const std::vector<cv::Point2f>& corners) {
  static double time = 0;
  selector.Offer({}, time += kFrame);
  selector.Offer(corners, time += kFrame);
  selector.Offer(corners, time += kFrame);
}

TEST(ViewSelector, BoardsOnlyInTheMiddleNeverSuffice) {
  ViewSelector selector(kBoard, kImage);
  for (int i = 0; i < 30; ++i) Show(selector, SeenBoard({0.01 * (i % 3), 0.01 * (i % 2), 0.5 + 0.02 * i}, i % 2 ? 0 : 5));
  const auto bars = selector.Bars();
  ASSERT_EQ(bars.size(), 4u);
  EXPECT_EQ(bars[0].name, "X");
  EXPECT_LT(bars[0].progress, 0.5);
  EXPECT_LT(bars[1].progress, 0.5);
  EXPECT_FALSE(selector.Sufficient());
}

TEST(ViewSelector, BoardsAcrossTheImageNearAndFarAndTiltedSuffice) {
  ViewSelector selector(kBoard, kImage);
  for (double x : {-0.2, 0.0, 0.2}) {
    for (double y : {-0.15, 0.0, 0.15}) {
      for (double z : {0.25, 0.7}) {
        for (double tilt : {0.0, 50.0}) Show(selector, SeenBoard({x * z / 0.5, y * z / 0.5, z}, tilt));
      }
    }
  }
  for (const CoverageBar& bar : selector.Bars()) EXPECT_DOUBLE_EQ(bar.progress, 1.0) << bar.name;
  EXPECT_GE(selector.taken().size(), 12u);
  EXPECT_TRUE(selector.Sufficient());
  EXPECT_EQ(selector.taken_corners().size(), selector.taken().size());
}

TEST(ViewSelector, EnoughViewsSufficeWhateverTheBars) {
  ViewSelectionOptions options;
  options.min_novelty = 0;  // every still frame is new
  options.min_views = 3;
  options.max_views = 5;
  ViewSelector selector(kBoard, kImage, options);
  for (int i = 0; i < 5; ++i) Show(selector, FlatBoard({100.f + i, 100}, 30));
  EXPECT_EQ(selector.taken().size(), 5u);
  EXPECT_TRUE(selector.Sufficient());
}

TEST(ViewSelectionOptions, ChecksNameTheField) {
  ViewSelectionOptions options;
  options.still_px_per_s = 0;
  try {
    options.Check(OptionNames({{"still_px_per_s", "--still"}, {"max_views", "--max-views"}}));
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "--still must be positive (got 0)");
  }
  options = {};
  options.max_views = 5;
  EXPECT_THROW(options.Check(), OptionError);
}

// The same board as places on it (row, column): what a ChArUco detection pairs its corners with.
std::vector<cv::Point3f> Places() {
  std::vector<cv::Point3f> places;
  for (int row = 0; row < kBoard.height; ++row) {
    for (int column = 0; column < kBoard.width; ++column) places.emplace_back(column * 0.025f, row * 0.025f, 0.f);
  }
  return places;
}

TEST(PlacePartialBoard, AWholeBoardInAnyOrderIsPlacedAsPlaceBoardPlacesIt) {
  const std::vector<cv::Point2f> corners = SeenBoard({0.05, -0.02, 0.6}, 30);
  std::vector<cv::Point2f> shuffled(corners.rbegin(), corners.rend());
  std::vector<cv::Point3f> places = Places();
  std::reverse(places.begin(), places.end());
  const BoardPlacement whole = PlaceBoard(corners, kBoard, kImage), part = PlacePartialBoard(shuffled, places, kImage);
  EXPECT_NEAR(part.x, whole.x, 1e-3);
  EXPECT_NEAR(part.y, whole.y, 1e-3);
  EXPECT_NEAR(part.size, whole.size, 1e-3);
  EXPECT_NEAR(part.skew, whole.skew, 1e-3);
}

TEST(PlacePartialBoard, TheLeftHalfIsSmallerAndFurtherLeft) {
  const std::vector<cv::Point2f> corners = SeenBoard({0, 0, 0.6}, 0);
  const std::vector<cv::Point3f> places = Places();
  std::vector<cv::Point2f> left;
  std::vector<cv::Point3f> left_places;
  for (size_t i = 0; i < corners.size(); ++i) {
    if (static_cast<int>(i) % kBoard.width < 4) {
      left.push_back(corners[i]);
      left_places.push_back(places[i]);
    }
  }
  const BoardPlacement whole = PlaceBoard(corners, kBoard, kImage), half = PlacePartialBoard(left, left_places, kImage);
  EXPECT_LT(half.size, 0.8 * whole.size);
  EXPECT_NEAR(half.skew, 0, 0.01);
  const cv::Point2f mean_left = std::accumulate(left.begin(), left.end(), cv::Point2f()) / static_cast<float>(left.size());
  EXPECT_LT(mean_left.x, 300);
  // Corners on one line fix no homography: no placement.
  EXPECT_TRUE(PartialBoardOutline({corners[0], corners[1], corners[2], corners[3]},
                                  {places[0], places[1], places[2], places[3]}).empty());
}

TEST(ViewSelector, APartialBoardHeldStillIsTakenWhateverTheOrderOfItsCorners) {
  ViewSelector selector(kBoard, kImage);
  const std::vector<cv::Point2f> corners = SeenBoard({0, 0, 0.6}, 20);
  std::vector<cv::Point2f> part(corners.begin(), corners.begin() + 20);
  const std::vector<cv::Point3f> all = Places();
  std::vector<cv::Point3f> places(all.begin(), all.begin() + 20);
  EXPECT_EQ(selector.OfferPartial(part, places, 0.0), ViewSelector::Decision::kMoving);
  std::reverse(part.begin(), part.end());
  std::reverse(places.begin(), places.end());
  EXPECT_EQ(selector.OfferPartial(part, places, 0.1), ViewSelector::Decision::kTaken);
  EXPECT_EQ(selector.taken_outlines().back().size(), 4u);
  // Five corners are not a board.
  part.resize(5);
  places.resize(5);
  EXPECT_EQ(selector.OfferPartial(part, places, 0.2), ViewSelector::Decision::kNoBoard);
}

}  // namespace
}  // namespace arview::calib
