#pragma once
// Choosing the views of a live calibration, as ROS camera_calibration does: each board seen is
// described by four numbers in [0, 1] (X and Y: where it sits across the image; size: how much of
// the image it fills; skew: how far it is tilted), a view is taken when the board is held still
// (its corners moved slower than a threshold since the previous frame, so that the view is not
// blurred) and when it differs from every view taken so far (the L1 distance of the four numbers),
// and the coverage of each number (the range the taken views span, against the range a good
// calibration needs) says when there are enough. Pure logic: corners in, decisions out.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/option_check.h"

namespace arview::calib {

// Where a board sits in the image: each in [0, 1].
struct BoardPlacement {
  double x = 0;     // the corners' mean across the image, from the left edge (0) to the right (1)
  double y = 0;     // the same from the top (0) to the bottom (1)
  double size = 0;  // the square root of the board's outline area over the image's area
  double skew = 0;  // 0: the outline's top-right corner a right angle; 1: 0.5 rad (29°) or more off it

  double Distance(const BoardPlacement& other) const;  // L1 over the four
};

// The outline of a chessboard's inner corners (`board`: per row, per column; corners row after
// row as calib::FindChessboardCorners gives them) placed in an image of `image_size`.
BoardPlacement PlaceBoard(const std::vector<cv::Point2f>& corners, cv::Size board, cv::Size image_size);

// The part of a board seen (a ChArUco board's corners found, at least 4, each with its place on
// the board, z = 0): the outline of the board's rectangle that holds them, carried into the image
// by the homography they fit, placed as PlaceBoard places a whole board's outline. A board half
// out of the image is placed by its visible half; its skew is the board's own.
BoardPlacement PlacePartialBoard(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board,
                                 cv::Size image_size);
// That outline, for drawing (four image points; empty when the corners fit no homography).
std::vector<cv::Point2f> PartialBoardOutline(const std::vector<cv::Point2f>& corners,
                                             const std::vector<cv::Point3f>& on_board);

// One coverage bar: the range of a placement number the taken views span, and how much of the
// range a calibration needs they cover (0..1).
struct CoverageBar {
  std::string name;  // "X", "Y", "size", "skew"
  double low = 0, high = 0;  // spanned so far
  double progress = 0;       // min(1, (high - low) / needed)
};

struct ViewSelectionOptions {
  // A board is still when its corners moved on average slower than this since the previous
  // frame (pixels a second at the camera's size): the smear within an exposure of 1/30 s (a
  // webcam's longest at 30 fps) stays under a pixel. A speed, not a distance between frames, so
  // that frames dropped by a reader that falls behind do not make a still board look moving.
  double still_px_per_s = 30;
  // A view is new when its placement is at least this far (L1) from every view taken (ROS's 0.2).
  double min_novelty = 0.2;
  // The spans a calibration needs of X, Y, size and skew (ROS's 0.7, 0.7, 0.4, 0.5).
  double needed_x = 0.7, needed_y = 0.7, needed_size = 0.4, needed_skew = 0.5;
  // Coverage suffices with every bar full and at least this many views; or with max_views
  // whatever the bars say (ROS: 40), since some placements cannot be reached with every lens.
  int min_views = 12;
  int max_views = 40;
  // A board seen in part counts with at least this many corners (ChArUco: calib's detection
  // keeps 6 or more).
  int min_partial_corners = 6;

  // Throws OptionError naming the first field out of range.
  void Check(const OptionNames& names = {}) const;
};

class ViewSelector {
 public:
  enum class Decision {
    kNoBoard,  // no board in the frame
    kMoving,   // a board, moving (or the first frame it was seen in: no motion known yet)
    kKnown,    // still, but too near a view already taken
    kTaken,    // still and new: taken
  };

  ViewSelector(cv::Size board, cv::Size image_size, ViewSelectionOptions options = {});

  // The next frame's corners (empty: no board found) and its time (seconds, increasing). A frame
  // without a board forgets the last corners, so that a board seen again is never still at once.
  Decision Offer(const std::vector<cv::Point2f>& corners, double timestamp);
  // The same for a board seen in part (ChArUco): its corners found (fewer than min_partial_corners:
  // no board) and their places on the board, which say which corner is which from frame to frame
  // (its stillness is measured on the corners seen in both).
  Decision OfferPartial(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board,
                        double timestamp);

  const std::vector<std::vector<cv::Point2f>>& taken_corners() const { return taken_corners_; }
  // Each view's outline in the image (four points): a chessboard's outer corners, a part's
  // PartialBoardOutline.
  const std::vector<std::vector<cv::Point2f>>& taken_outlines() const { return taken_outlines_; }
  const std::vector<BoardPlacement>& taken() const { return taken_; }
  std::vector<CoverageBar> Bars() const;  // X, Y, size, skew
  bool Sufficient() const;
  // The corners' average speed at the last offer (pixels a second; negative when not known).
  double last_speed_px_per_s() const { return last_speed_; }

 private:
  // The corners' mean speed since the last frame over the corners seen in both (by their place on
  // the board); negative when fewer than 4 are.
  double SpeedSince(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board,
                    double timestamp) const;
  Decision Decide(const std::vector<cv::Point2f>& corners, const std::vector<cv::Point3f>& on_board, double timestamp,
                  const BoardPlacement& placement, std::vector<cv::Point2f> outline);

  cv::Size board_, image_size_;
  ViewSelectionOptions options_;
  std::vector<cv::Point2f> previous_;
  std::vector<cv::Point3f> previous_on_board_;
  double previous_time_ = 0;
  double last_speed_ = -1;
  std::vector<BoardPlacement> taken_;
  std::vector<std::vector<cv::Point2f>> taken_corners_;
  std::vector<std::vector<cv::Point2f>> taken_outlines_;
};

}  // namespace arview::calib
