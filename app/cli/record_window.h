#pragma once
// The window of `arview record --window`: the camera's picture with the points the capture
// guidance follows, and beside it what the guidance makes of the footage so far (the views kept
// and how many steps between them had parallax, the picture's speed against the blur limit, the
// features against what a map needs) and what to do now (recordings/capture_guidance.h).

#include <string>

#include <opencv2/core.hpp>

#include "recordings/capture_guidance.h"

namespace arview::app {

struct RecordWindowStatus {
  double seconds = 0;  // recorded so far
  int frames = 0;
};

// The window's size for frames of `frame_size`.
cv::Size RecordWindowSize(cv::Size frame_size);

// The window's picture for `frame` (BGR, the recording's size).
cv::Mat DrawRecordWindow(const cv::Mat& frame, const recordings::CaptureGuidance& guidance,
                         const recordings::CaptureGuidanceOptions& options, const RecordWindowStatus& status);

}  // namespace arview::app
