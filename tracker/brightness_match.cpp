#include "tracker/brightness_match.h"

#include <cmath>

namespace arview::tracker {

cv::Mat MatchMeanBrightness(const cv::Mat& gray, const cv::Mat& reference, double tolerance) {
  if (reference.empty() || gray.empty()) return gray;
  const double own = cv::mean(gray)[0], wanted = cv::mean(reference)[0];
  if (own < 1.0 || wanted < 1.0) return gray;  // a black frame: nothing to scale
  const double gain = wanted / own;
  if (std::abs(gain - 1.0) <= tolerance) return gray;
  cv::Mat scaled;
  gray.convertTo(scaled, CV_8U, gain);
  return scaled;
}

}  // namespace arview::tracker
