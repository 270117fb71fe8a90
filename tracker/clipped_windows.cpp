#include "tracker/clipped_windows.h"

#include <algorithm>
#include <cmath>

namespace arview::tracker {

void ClippedWindowOptions::Check(const OptionNames& names) const {
  RequireOption(max_share > 0 && max_share <= 1, names("max_share"), "in (0, 1]", max_share);
  RequireOption(clip_grey >= 1 && clip_grey <= 255, names("clip_grey"), "in 1..255", clip_grey);
}

std::vector<bool> MostlyClipped(const cv::Mat& gray, std::span<const Eigen::Vector2d> pixels, int window_px,
                                const ClippedWindowOptions& options) {
  std::vector<bool> clipped(pixels.size(), false);
  if (options.max_share >= 1 || gray.empty()) return clipped;
  CV_Assert(gray.type() == CV_8UC1);
  const int half = window_px / 2;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const int cx = static_cast<int>(std::lround(pixels[i].x()));
    const int cy = static_cast<int>(std::lround(pixels[i].y()));
    const int x0 = std::clamp(cx - half, 0, gray.cols - 1), x1 = std::clamp(cx + half, 0, gray.cols - 1);
    const int y0 = std::clamp(cy - half, 0, gray.rows - 1), y1 = std::clamp(cy + half, 0, gray.rows - 1);
    int white = 0;
    for (int y = y0; y <= y1; ++y) {
      const std::uint8_t* row = gray.ptr<std::uint8_t>(y);
      for (int x = x0; x <= x1; ++x) white += row[x] >= options.clip_grey;
    }
    const int area = (x1 - x0 + 1) * (y1 - y0 + 1);
    clipped[i] = white > options.max_share * area;
  }
  return clipped;
}

}  // namespace arview::tracker
