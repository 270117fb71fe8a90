#include "calib/board_views.h"

#include <algorithm>
#include <cmath>
#include <numbers>

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

}  // namespace

BoardPlacement PlaceBoard(const std::vector<cv::Point2f>& corners, cv::Size board, cv::Size image_size) {
  const cv::Point2d up_left = corners.front(), up_right = corners[board.width - 1];
  const cv::Point2d down_right = corners.back(), down_left = corners[corners.size() - board.width];
  // The outline's area from its two diagonals (a quadrilateral's area is half their cross product).
  const cv::Point2d diagonal_a = down_right - up_left, diagonal_b = down_left - up_right;
  const double area = std::abs(diagonal_a.x * diagonal_b.y - diagonal_a.y * diagonal_b.x) / 2;
  cv::Point2d mean(0, 0);
  for (const cv::Point2f& p : corners) mean += cv::Point2d(p);
  mean *= 1.0 / corners.size();
  // As ROS: the mean is measured within the range a board of this size can move in, so that a
  // large board touching both edges is at 0.5, and a small one at an edge near 0 or 1.
  const double border = std::sqrt(area);
  BoardPlacement placement;
  placement.x = std::clamp((mean.x - border / 2) / std::max(1.0, image_size.width - border), 0.0, 1.0);
  placement.y = std::clamp((mean.y - border / 2) / std::max(1.0, image_size.height - border), 0.0, 1.0);
  placement.size = std::sqrt(area / (static_cast<double>(image_size.width) * image_size.height));
  placement.skew = std::min(1.0, 2 * std::abs(std::numbers::pi / 2 - AngleAt(up_left, up_right, down_right)));
  return placement;
}

void ViewSelectionOptions::Check(const OptionNames& names) const {
  RequireOption(still_px_per_s > 0, names("still_px_per_s"), "positive", still_px_per_s);
  RequireOption(min_novelty >= 0, names("min_novelty"), "0 or more", min_novelty);
  for (const auto& [field, value] : {std::pair{"needed_x", needed_x}, std::pair{"needed_y", needed_y},
                                     std::pair{"needed_size", needed_size}, std::pair{"needed_skew", needed_skew}}) {
    RequireOption(value > 0 && value <= 1, names(field), "in (0, 1]", value);
  }
  RequireOption(min_views >= 3, names("min_views"), "at least 3", min_views);
  RequireOption(max_views >= min_views, names("max_views"), "at least min_views (" + std::to_string(min_views) + ")",
                max_views);
}

ViewSelector::ViewSelector(cv::Size board, cv::Size image_size, ViewSelectionOptions options)
    : board_(board), image_size_(image_size), options_(options) {
  options_.Check();
}

ViewSelector::Decision ViewSelector::Offer(const std::vector<cv::Point2f>& corners, double timestamp) {
  last_speed_ = -1;
  if (corners.size() != static_cast<size_t>(board_.area())) {
    previous_.clear();
    return Decision::kNoBoard;
  }
  const double interval = timestamp - previous_time_;
  if (previous_.size() == corners.size() && interval > 0) {
    double motion = 0;
    for (size_t i = 0; i < corners.size(); ++i) motion += cv::norm(corners[i] - previous_[i]);
    last_speed_ = motion / corners.size() / interval;
  }
  previous_ = corners;
  previous_time_ = timestamp;
  if (last_speed_ < 0 || last_speed_ >= options_.still_px_per_s) return Decision::kMoving;
  const BoardPlacement placement = PlaceBoard(corners, board_, image_size_);
  for (const BoardPlacement& known : taken_) {
    if (placement.Distance(known) < options_.min_novelty) return Decision::kKnown;
  }
  taken_.push_back(placement);
  taken_corners_.push_back(corners);
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
