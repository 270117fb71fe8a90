#pragma once
// A light change between two frames (a lamp switched off, the camera's exposure stepping, a
// cloud) breaks the brightness constancy LK assumes: every patch darkens or brightens at once, LK
// follows them badly, and the frame's pose fails the residual gate and is relocalised. So the
// frame LK follows into is first scaled to the previous flow image's mean grey, when the two
// differ by more than a tolerance (ordinary frames are left exactly as they are). SIFT (guided
// matching, relocalization) is invariant to such a gain and sees the frame as it is.

#include <opencv2/core.hpp>

namespace arview::tracker {

struct BrightnessMatch {
  cv::Mat image;      // the frame LK follows into
  double gain = 1.0;  // what `image` was scaled by (1: it is the frame itself)
  // The light changed beyond the tolerance: the frame was scaled, and its patches (clipped,
  // shadowed unevenly) fit the last frame's less exactly than a steady frame's do.
  bool light_changed() const { return gain != 1.0; }
};

// `gray` (8-bit) scaled by mean(reference) / mean(gray) (saturating) when that ratio is off 1 by
// more than `tolerance`; otherwise `gray` itself. An empty reference or a black frame: `gray`.
BrightnessMatch MatchMeanBrightness(const cv::Mat& gray, const cv::Mat& reference, double tolerance);

}  // namespace arview::tracker
