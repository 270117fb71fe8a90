#pragma once
// Where augmented frames go: a window (OpenCV highgui), an MP4 file (OpenCV's FFmpeg writer),
// or a folder of PNGs. OpenSink picks by the target's form:
//   "window" or "window:<title>"  → a highgui window (no display → RenderError saying so)
//   "null"                         → frames counted and discarded (soak runs, timing)
//   "<file>.mp4" | ".avi" | ".mkv" → a video file at the given frame rate
//   "<folder>/" or an existing folder or a name without extension → <folder>/000000.png, ...

#include <opencv2/core.hpp>

#include <memory>
#include <string>

namespace arview::video {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Throws RenderError naming the target when the frame cannot be written (or, for a window,
  // shown). Every frame must have the size given at opening.
  virtual void Write(const cv::Mat& bgr) = 0;
  // Flushes and closes; safe to call twice. Destruction closes too, without throwing.
  virtual void Close() = 0;
  // For a window: whether the user asked to stop (Esc or q, or closed the window).
  virtual bool StopRequested() const { return false; }
  virtual std::string Describe() const = 0;
};

std::unique_ptr<FrameSink> OpenSink(const std::string& target, cv::Size frame_size, double fps);

// Whether a display is available for highgui windows (DISPLAY or WAYLAND_DISPLAY set).
bool HasDisplay();

}  // namespace arview::video
