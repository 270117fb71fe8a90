#include "tracker/brightness_match.h"

#include <cmath>

namespace arview::tracker {

BrightnessMatch MatchMeanBrightness(const cv::Mat& gray, const cv::Mat& reference, double tolerance) {
  if (reference.empty() || gray.empty()) return {gray};
  const double own = cv::mean(gray)[0], wanted = cv::mean(reference)[0];
  if (own < 1.0 || wanted < 1.0) return {gray};  // a black frame: nothing to scale
  const double gain = wanted / own;
  if (std::abs(gain - 1.0) <= tolerance) return {gray};
  BrightnessMatch matched{cv::Mat(), gain};
  gray.convertTo(matched.image, CV_8U, gain);
  return matched;
}

}  // namespace arview::tracker
