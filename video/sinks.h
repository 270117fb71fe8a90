#pragma once
// Where augmented frames go: a window (video/window.h), an MP4 file (libx264, else OpenCV's
// FFmpeg writer), or a folder of PNGs. OpenSink picks by the target's form:
//   "window" or "window:<title>"  → an X11 window (no display → VideoError saying so)
//   "null"                         → frames counted and discarded (soak runs, timing)
//   "<file>.mp4" | ".avi" | ".mkv" → a video file at the given frame rate
//   "<folder>/" or an existing folder or a name without extension → <folder>/000000.png, ...

#include <opencv2/core.hpp>

#include "video/h264_writer.h"
#include "video/window.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

namespace arview::video {

// Frame `index` of a PNG folder the sink writes (<folder>/000000.png, ...), for whoever reads it back.
std::filesystem::path PngFrameFile(const std::filesystem::path& folder, int index);

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Throws VideoError naming the target when the frame cannot be written (or, for a window,
  // shown). Every frame must have the size given at opening.
  virtual void Write(const cv::Mat& bgr) = 0;
  // Flushes and closes; safe to call twice. Destruction closes too, without throwing.
  virtual void Close() = 0;
  // For a window: whether the user asked to stop (Esc or q, or closed the window). Safe to
  // call from any thread.
  virtual bool StopRequested() const { return false; }
  virtual std::string Describe() const = 0;

  // Whether the sink writes an audio track: an MP4, MKV or AVI file opened with one (OpenSink's
  // `audio`) through libx264's writer. The others have none.
  virtual bool HasAudio() const { return false; }
  // Mono samples at the track's rate, the first heard first_sample / rate seconds after the first
  // frame (H264Writer::WriteAudio: overlaps summed, gaps silent, late audio dropped and counted).
  // Called on the thread that writes the frames, between frames. A sink without audio throws
  // VideoError naming its target.
  virtual void WriteAudio(std::int64_t first_sample, std::span<const std::int16_t> samples);
  // Samples WriteAudio dropped: before the start, or in audio already written.
  virtual std::int64_t AudioSamplesDropped() const { return 0; }

  // A window is used by one thread at a time: it is opened by OpenSink, then Write, PumpEvents
  // and SetStatus come from the thread that writes the frames, then Close from the opener once
  // that thread has ended.
  //
  // Reads the window's events (keys, close, expose) without a frame: the writing thread calls
  // it when no frame came for a while, so that Esc works and an uncovered window is repainted
  // while the camera stalls. Write reads them too.
  virtual void PumpEvents() {}
  // A short live status (frame rate, latency, drops): a window shows it in its title.
  virtual void SetStatus(const std::string& /*status*/) {}
  // Keys other than those that stop (Esc, q) go here, as X keysym names ("h", "F1"); called on
  // the writing thread.
  void SetKeyHandler(std::function<void(const std::string& key)> handler) { key_handler_ = std::move(handler); }

 protected:
  std::function<void(const std::string&)> key_handler_;
};

// `window` places a window target (video/window.h); other targets ignore it. `audio`: a video
// file gets an AAC track with these options (a VideoError naming the file when only OpenCV's
// writer is at hand, which writes no audio); other targets have none (HasAudio is false).
std::unique_ptr<FrameSink> OpenSink(const std::string& target, cv::Size frame_size, double fps,
                                    const WindowPlacement& window = {},
                                    const std::optional<AudioTrackOptions>& audio = std::nullopt);

// Whether `target` names a window ("window" or "window:<title>").
bool IsWindowTarget(const std::string& target);

// Whether a display is available for the window (DISPLAY set: an X server, or Xwayland).
bool HasDisplay();

}  // namespace arview::video
