#pragma once
// The text panel beside the camera's picture in the windows of `arview calibrate` and `arview
// record`: lines of words broken to the panel's width, and labelled bars.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace arview::app {

// `text` in lines of at most `width` characters, broken between words.
std::vector<std::string> WrapWords(const std::string& text, size_t width);

// A bar at `outline` filled to `progress` (0 to 1) in `colour`, its outline light grey.
void DrawBar(cv::Mat& picture, const cv::Rect& outline, double progress, const cv::Scalar& colour);

}  // namespace arview::app
