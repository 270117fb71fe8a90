#include "app/cli/window_panel.h"

#include <algorithm>
#include <sstream>

#include <opencv2/imgproc.hpp>

namespace arview::app {

std::vector<std::string> WrapWords(const std::string& text, size_t width) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void DrawBar(cv::Mat& picture, const cv::Rect& outline, double progress, const cv::Scalar& colour) {
  const int filled = static_cast<int>(outline.width * std::clamp(progress, 0.0, 1.0));
  cv::rectangle(picture, {outline.x, outline.y, filled, outline.height}, colour, cv::FILLED);
  cv::rectangle(picture, outline, {200, 200, 200}, 1);
}

}  // namespace arview::app
