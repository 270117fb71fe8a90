#include "calib/board_views.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/calib3d.hpp>

namespace arview::calib {

double BoardPlacement::Distance(const BoardPlacement& other) const {
  return std::abs(x - other.x) + std::abs(y - other.y) + std::abs(size - other.size) + std::abs(skew - other.skew);
}

namespace {

// The angle at b between the edges to a and to c (radians).
double AngleAt(cv::Point2d a, cv::Point2d b, cv::Point2d c) {
  const cv::Point2d ab = a - b, cb = c - b;
  const double cosine = ab.dot(cb) / (std::hypot(ab.x, ab.y) * std::hypot(cb.x, cb.y));
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

// A board's outline (up left, up right, down right, down left) and the mean of its corners placed
// in the image.
BoardPlacement PlaceOutline(const std::vector<cv::Point2f>& outline, cv::Point2d mean, cv::Size image_size) {
  const cv::Point2d up_left = outline[0], up_right = outline[1], down_right = outline[2], down_left = outline[3];
  // The outline's area from its two diagonals (a quadrilateral's area is half their cross product).
  const cv::Point2d diagonal_a = down_right - up_left, diagonal_b = down_left - up_right;
  const double area = std::abs(diagonal_a.x * diagonal_b.y - diagonal_a.y * diagonal_b.x) / 2;
  // As ROS: the mean is measured within the range a board of this size can move in, so that a
  // large board touching both edges is at 0.5, and a small one at an edge near 0 or 1.
  const double border = std::sqrt(area);
  BoardPlacement placement;
  placement.x = std::clamp((mean.x - border / 2) / std::max(1.0, image_size.width - border), 0.0, 1.0);
  placement.y = std::clamp((mean.y - border / 2) / std::max(1.0, image_size.height - border), 0.0, 1.0);
  placement.size = std::min(1.0, std::sqrt(area / (static_cast<double>(image_size.width) * image_size.height)));
  placement.skew = std::min(1.0, 2 * std::abs(std::numbers::pi / 2 - AngleAt(up_left, up_right, down_right)));
  return placement;
}

cv::Point2d Mean(const std::vector<cv::Point2f>& corners) {
  cv::Point2d mean(0, 0);
  for (const cv::Point2f& p : corners) mean += cv::Point2d(p);
  return mean * (1.0 / corners.size());
}

std::vector<cv::Point2f> ChessboardOutline(const std::vector<cv::Point2f>& corners, cv::Size board) {
  return {corners.front(), corners[board.width - 1], corners.back(), corners[corners.size() - board.width]};
}

}  // namespace

BoardPlacement PlaceBoard(const std::vector<cv::Point2f>& corners, cv::Size board, cv::Size image_size) {
  return PlaceOutline(ChessboardOutline(corners, board), Mean(corners), image_size);
}

std::vector<cv::Point2f> PartialBoardOutline(const std::vector<cv::Point2f>& corners,
                                             const std::vector<cv::Point3f>& on_board) {
  if (corners.size() < 4 || corners.size() != on_board.size()) return {};
  std::vector<cv::Point2f> plane;
  float left = on_board[0].x, right = left, top = on_board[0].y, bottom = top;
  for (const cv::Point3f& p : on_board) {
    plane.emplace_back(p.x, p.y);
    left = std::min(left, p.x);
    right = std::max(right, p.x);
    top = std::min(top, p.y);
    bottom = std::max(bottom, p.y);
  }
  if (right <= left || bottom <= top) return {};  // corners on one line fix no homography
  const cv::Mat h = cv::findHomography(plane, corners);
  if (h.empty()) return {};
  std::vector<cv::Point2f> outline;
  cv::perspectiveTransform(std::vector<cv::Point2f>{{left, top}, {right, top}, {right, bottom}, {left, bottom}},
                           outline, h);
  return outline;
}

BoardPlacement PlacePartialBoard(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board,
                                 cv::Size image_size) {
  const std::vector<cv::Point2f> outline = PartialBoardOutline(corners, on_board);
  if (outline.empty()) return {};
  return PlaceOutline(outline, Mean(corners), image_size);
}

void ViewSelectionOptions::Check(const OptionNames& names) const {
  RequireOption(still_px_per_s > 0, names("still_px_per_s"), "positive", still_px_per_s);
  RequireOption(min_novelty >= 0, names("min_novelty"), "0 or more", min_novelty);
  for (const auto& [field, value] : {std::pair{"needed_x", needed_x}, std::pair{"needed_y", needed_y},
                                     std::pair{"needed_size", needed_size}, std::pair{"needed_skew", needed_skew}}) {
    RequireOption(value > 0 && value <= 1, names(field), "in (0, 1]", value);
  }
  RequireOption(min_views >= 3, names("min_views"), "at least 3", min_views);
  RequireOption(min_partial_corners >= 4, names("min_partial_corners"), "at least 4", min_partial_corners);
  RequireOption(max_views >= min_views, names("max_views"), "at least min_views (" + std::to_string(min_views) + ")",
                max_views);
}

ViewSelector::ViewSelector(cv::Size board, cv::Size image_size, ViewSelectionOptions options)
    : board_(board), image_size_(image_size), options_(options) {
  options_.Check();
}

ViewSelector::Decision ViewSelector::Offer(const std::vector<cv::Point2f>& corners, double timestamp) {
  if (corners.size() != static_cast<size_t>(board_.area())) return Decide({}, {}, timestamp, {}, {});
  // Each corner's place is its row and column: the same corner from frame to frame.
  std::vector<cv::Point3f> grid;
  for (int row = 0; row < board_.height; ++row) {
    for (int column = 0; column < board_.width; ++column) grid.emplace_back(column, row, 0);
  }
  return Decide(corners, grid, timestamp, PlaceBoard(corners, board_, image_size_), ChessboardOutline(corners, board_));
}

ViewSelector::Decision ViewSelector::OfferPartial(const std::vector<cv::Point2f>& corners,
                                                  const std::vector<cv::Point3f>& on_board, double timestamp) {
  std::vector<cv::Point2f> outline = PartialBoardOutline(corners, on_board);
  if (static_cast<int>(corners.size()) < options_.min_partial_corners || outline.empty()) {
    return Decide({}, {}, timestamp, {}, {});
  }
  const BoardPlacement placement = PlaceOutline(outline, Mean(corners), image_size_);
  return Decide(corners, on_board, timestamp, placement, std::move(outline));
}

double ViewSelector::SpeedSince(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board,
                                double timestamp) const {
  const double interval = timestamp - previous_time_;
  if (interval <= 0) return -1;
  double motion = 0;
  int common = 0;
  for (size_t i = 0; i < corners.size(); ++i) {
    // The same corner in the frame before: at the same index for a whole board, else searched.
    const bool same_index = i < previous_on_board_.size() && previous_on_board_[i] == on_board[i];
    const auto it = same_index ? previous_on_board_.begin() + static_cast<std::ptrdiff_t>(i)
                               : std::find(previous_on_board_.begin(), previous_on_board_.end(), on_board[i]);
    if (it == previous_on_board_.end()) continue;
    motion += cv::norm(corners[i] - previous_[static_cast<size_t>(it - previous_on_board_.begin())]);
    ++common;
  }
  return common >= 4 ? motion / common / interval : -1;
}

ViewSelector::Decision ViewSelector::Decide(const std::vector<cv::Point2f>& corners,
                                            const std::vector<cv::Point3f>& on_board, double timestamp,
                                            const BoardPlacement& placement, std::vector<cv::Point2f> outline) {
  last_speed_ = -1;
  if (corners.empty()) {
    previous_.clear();
    previous_on_board_.clear();
    return Decision::kNoBoard;
  }
  last_speed_ = SpeedSince(corners, on_board, timestamp);
  previous_ = corners;
  previous_on_board_ = on_board;
  previous_time_ = timestamp;
  if (last_speed_ < 0 || last_speed_ >= options_.still_px_per_s) return Decision::kMoving;
  for (const BoardPlacement& known : taken_) {
    if (placement.Distance(known) < options_.min_novelty) return Decision::kKnown;
  }
  taken_.push_back(placement);
  taken_corners_.push_back(corners);
  taken_outlines_.push_back(std::move(outline));
  return Decision::kTaken;
}

std::vector<CoverageBar> ViewSelector::Bars() const {
  std::vector<CoverageBar> bars = {{"X"}, {"Y"}, {"size"}, {"skew"}};
  if (taken_.empty()) return bars;
  auto span = [&](CoverageBar& bar, double BoardPlacement::*field, double needed, bool from_zero) {
    bar.low = from_zero ? 0.0 : 1.0;
    bar.high = 0;
    for (const BoardPlacement& p : taken_) {
      bar.low = std::min(bar.low, p.*field);
      bar.high = std::max(bar.high, p.*field);
    }
    bar.progress = std::min(1.0, (bar.high - bar.low) / needed);
  };
  span(bars[0], &BoardPlacement::x, options_.needed_x, false);
  span(bars[1], &BoardPlacement::y, options_.needed_y, false);
  span(bars[2], &BoardPlacement::size, options_.needed_size, false);
  // Skew counts from facing the camera (0), as ROS counts it: a tilted view is what is needed.
  span(bars[3], &BoardPlacement::skew, options_.needed_skew, true);
  return bars;
}

bool ViewSelector::Sufficient() const {
  const int n = static_cast<int>(taken_.size());
  if (n >= options_.max_views) return true;
  if (n < options_.min_views) return false;
  for (const CoverageBar& bar : Bars()) {
    if (bar.progress < 1.0) return false;
  }
  return true;
}

}  // namespace arview::calib
