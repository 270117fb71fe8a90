#include "app/cli/live_calibration.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

namespace arview::app {
namespace {

// Pixels of the window's frame in the overlay's green (BGR 60, 220, 60, give or take its
// anti-aliasing), within `area`.
int GreenPixels(const cv::Mat& window, const cv::Rect& area) {
  cv::Mat green;
  cv::inRange(window(area), cv::Scalar(40, 200, 40), cv::Scalar(80, 240, 80), green);
  return cv::countNonZero(green);
}

// Part of a 10x7 ChArUco board found: 4 x 3 of its corners, 40 px apart, from (200, 150).
calib::BoardDetection PartOfABoard() {
  calib::BoardDetection found;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 4; ++column) {
      found.image_points.emplace_back(200 + 40 * column, 150 + 40 * row);
      found.object_points.emplace_back(0.05f * (column + 2), 0.05f * (row + 1), 0.0f);
    }
  }
  return found;
}

TEST(CalibrationWindow, OutlinesThePartOfAChArUcoBoardFoundAndRingsItsCorners) {
  calib::CalibrationOptions board;
  board.kind = calib::BoardKind::kCharuco;
  board.board = {10, 7};
  board.square_size = 0.05;
  const calib::ViewSelector selector(board.board, {640, 480});
  const cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(110, 110, 110));
  const cv::Mat window = DrawCalibrationWindow(frame, PartOfABoard(), board, selector, "");
  // The outline's edges, away from the corners' dots: the top edge between two corners and the
  // left edge between two rows.
  EXPECT_GT(GreenPixels(window, {205, 145, 30, 10}), 40) << "no outline along the top";
  EXPECT_GT(GreenPixels(window, {195, 155, 10, 30}), 40) << "no outline along the left";
  // A corner: green inside, black round it.
  EXPECT_EQ(window.at<cv::Vec3b>(190, 280), cv::Vec3b(60, 220, 60));
  const cv::Vec3b ring = window.at<cv::Vec3b>(190, 284);
  EXPECT_LT(ring[0] + ring[1] + ring[2], 90) << ring;
  // Nothing green far from the board.
  EXPECT_EQ(GreenPixels(window, {400, 300, 200, 150}), 0);
}

TEST(CalibrationWindow, DrawsNoOutlineWithoutABoard) {
  calib::CalibrationOptions board;
  board.kind = calib::BoardKind::kCharuco;
  board.board = {10, 7};
  const calib::ViewSelector selector(board.board, {640, 480});
  const cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(110, 110, 110));
  const cv::Mat window = DrawCalibrationWindow(frame, {}, board, selector, "");
  EXPECT_EQ(GreenPixels(window, {0, 0, 640, 480}), 0);
}

}  // namespace
}  // namespace arview::app
