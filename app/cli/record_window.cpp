#include "app/cli/record_window.h"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "app/cli/window_panel.h"

namespace arview::app {

namespace {

constexpr int kPanelWidth = 260;

const cv::Scalar kGood(60, 200, 60), kBad(40, 60, 230), kText(235, 235, 235), kAdvice(120, 230, 255);

}  // namespace

cv::Size RecordWindowSize(cv::Size frame_size) {
  return {frame_size.width + kPanelWidth, std::max(frame_size.height, 360)};
}

cv::Mat DrawRecordWindow(const cv::Mat& frame, const recordings::CaptureGuidance& guidance,
                         const recordings::CaptureGuidanceOptions& options, const RecordWindowStatus& status) {
  cv::Mat picture(RecordWindowSize(frame.size()), CV_8UC3, cv::Scalar(40, 40, 40));
  cv::Mat shown = picture(cv::Rect({0, 0}, frame.size()));
  frame.copyTo(shown);
  const recordings::FrameGuidance& last = guidance.last();
  for (const cv::Point2f& p : last.points) cv::circle(shown, p, 2, {60, 220, 60}, cv::FILLED, cv::LINE_AA);

  const int left = frame.cols + 16, bar_left = left + 80, bar_width = kPanelWidth - 32 - 80;
  const auto text = [&](const std::string& line, int y, double scale = 0.5, cv::Scalar colour = kText) {
    cv::putText(picture, line, {left, y}, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
  };
  char line[96];
  text("capture guidance", 28, 0.65);
  std::snprintf(line, sizeof line, "%.1f s, %d frames", status.seconds, status.frames);
  text(line, 54);
  // The picture's speed against the smear a map tolerates: red beyond it.
  text("speed", 88);
  const double speed = last.smear_px / options.max_smear_px;
  DrawBar(picture, {bar_left, 74, bar_width, 18}, speed / 2, last.too_fast ? kBad : kGood);
  cv::line(picture, {bar_left + bar_width / 2, 70}, {bar_left + bar_width / 2, 96}, kText, 1);
  // Features against twice what a map needs: red below the mark.
  text("features", 122);
  DrawBar(picture, {bar_left, 108, bar_width, 18}, last.corners / (2.0 * std::max(options.min_corners, 1)),
          last.few_features ? kBad : kGood);
  cv::line(picture, {bar_left + bar_width / 2, 104}, {bar_left + bar_width / 2, 130}, kText, 1);
  // The steps between views with parallax: what the map is made from.
  text("parallax", 156);
  const int steps = guidance.steps();
  const double share = steps > 0 ? static_cast<double>(guidance.steps_with_parallax()) / steps : 0;
  DrawBar(picture, {bar_left, 142, bar_width, 18}, share, share >= options.min_parallax_share ? kGood : kBad);
  std::snprintf(line, sizeof line, "views: %d (%d of %d steps", guidance.views(), guidance.steps_with_parallax(), steps);
  text(line, 190);
  text("with parallax)", 210);
  text("q: stop (the recording stays)", 240, 0.45, {180, 180, 180});
  const std::string advice = guidance.Advice();
  int y = 274;
  for (const std::string& advice_line : WrapWords(advice.empty() ? "good: keep moving through the room" : advice, 26)) {
    text(advice_line, y, 0.5, advice.empty() ? kGood : kAdvice);
    y += 20;
  }
  return picture;
}

}  // namespace arview::app
