#pragma once
// A light change between two frames (a lamp switched off, the camera's exposure stepping, a
// cloud) breaks the brightness constancy LK assumes: every patch darkens or brightens at once, LK
// follows them badly, and the frame's pose fails the residual gate and is relocalised. So the
// frame LK follows into is first scaled to the previous flow image's mean grey, when the two
// differ by more than a tolerance (ordinary frames are left exactly as they are). SIFT (guided
// matching, relocalization) is invariant to such a gain and sees the frame as it is.

#include <opencv2/core.hpp>

namespace arview::tracker {

// `gray` (8-bit) scaled by mean(reference) / mean(gray) (saturating) when that ratio is off 1 by
// more than `tolerance`; otherwise `gray` itself. An empty reference or a black frame: `gray`.
cv::Mat MatchMeanBrightness(const cv::Mat& gray, const cv::Mat& reference, double tolerance);

}  // namespace arview::tracker
