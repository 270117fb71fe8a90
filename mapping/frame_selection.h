#pragma once
// Choosing which frames of a recording go to COLMAP. For a video: drop blurred frames (variance
// of the Laplacian well below that of their neighbours), drop near-duplicates of the previous kept
// frame (the camera did not move), then cap the count by keeping the sharpest frame of each of
// `max_frames` equal stretches of the video.

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

#include "recordings/recording.h"

namespace arview::mapping {

struct FrameSelectionOptions {
  // A frame is blurred when its sharpness is below this fraction of the median sharpness of
  // the frames around it (a window of `blur_window` frames).
  double blur_ratio = 0.5;
  int blur_window = 31;
  // A frame is a near-duplicate when the mean absolute difference of its 64x48 grey thumbnail
  // and the previous kept frame's is below this many grey levels.
  double duplicate_threshold = 2.0;
  int max_frames = 300;  // 0: no cap
};

// Per-frame measurements (computed from a grey image downscaled to at most 640 px wide).
struct FrameQuality {
  double sharpness = 0;  // variance of the Laplacian
  cv::Mat thumbnail;     // 64x48 CV_8U grey
};

FrameQuality MeasureFrame(const cv::Mat& image);

struct FrameSelection {
  std::vector<int> frames;  // selected indices, increasing
  int blurred = 0;          // dropped as blurred
  int duplicates = 0;       // dropped as near-duplicates
  int capped = 0;           // dropped by the cap
};

// Selection over already measured frames `candidates` (indices into `quality`, increasing).
FrameSelection SelectFrames(const std::vector<FrameQuality>& quality, const std::vector<int>& candidates,
                            const FrameSelectionOptions& options);

// Keeps at most `max_frames` of `frames`, evenly spread (for still-image recordings, whose frames
// were chosen by a person and are not filtered). max_frames <= 0 keeps all.
std::vector<int> CapEvenly(const std::vector<int>& frames, int max_frames);

// Reads a video recording once, measuring every frame, and selects among `candidates` (all
// frames when empty). `on_progress(done, total)` is called as frames are read.
// Throws recordings::RecordingError when the video cannot be read.
FrameSelection SelectVideoFrames(const recordings::Recording& recording, const std::vector<int>& candidates,
                                 const FrameSelectionOptions& options,
                                 const std::function<void(int, int)>& on_progress = {});

}  // namespace arview::mapping
