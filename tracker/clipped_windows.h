#pragma once
// Flow tracks whose LK window lies mostly on pixels the frame clips white: a lamp switched back on
// under an exposure raised for the dark whites out whole surfaces, LK's patch there has lost its
// texture, and where it ends is not the point's (the relit frames' poses fit at 1.1-1.4 px against
// a 1 px gate; docs/tracker.md, "Third round"). Judged on the window, not the track's one pixel:
// a track beside a bright spot, whose window keeps its texture, is right (dropping every track on
// a clipped pixel cost the lamp-lit frames right tracks).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <span>
#include <vector>

#include "base/option_check.h"

namespace arview::tracker {

struct ClippedWindowOptions {
  // A track is dropped when more than this share of LK's window around it is clipped; 1: off.
  double max_share = 1.0;
  int clip_grey = 250;  // grey level (of 255) from which a pixel counts as clipped

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

// Per pixel of `pixels` (in `gray`, 8-bit): whether more than options.max_share of the
// window_px x window_px window around it (clamped to the image) is at or above clip_grey.
std::vector<bool> MostlyClipped(const cv::Mat& gray, std::span<const Eigen::Vector2d> pixels, int window_px,
                                const ClippedWindowOptions& options);

}  // namespace arview::tracker
