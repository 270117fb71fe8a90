#pragma once
// An H.264 file written with FFmpeg's libraries directly (libx264 through libavcodec, muxed by
// libavformat), for the video sink: OpenCV's FFmpeg writer (4.6) opens x264 with its default
// preset, medium, and passes it no options. Medium cost 16 ms of CPU per 640x480 frame —
// trellis quantisation most of it — as much as rendering the frame, on the two cores that
// tracking and rendering share. Superfast at the same quality setting costs about 3 ms
// (docs/render.md, "Output sinks"). One encoder thread: the sink stage's time is then the
// encoder's whole cost, and it does not take CPU from the other stages behind their back.

#include <opencv2/core.hpp>

#include <filesystem>
#include <memory>
#include <string>

namespace arview::video {

struct H264Options {
  std::string preset = "superfast";  // x264's speed/compression trade-off
  int crf = 23;                      // x264's constant-quality setting (its default)
};

class H264Writer {
 public:
  // Nothing when this FFmpeg has no libx264 encoder or the size is odd (the caller then falls
  // back to OpenCV's writer); throws VideoError naming the file when the file cannot be opened or written.
  static std::unique_ptr<H264Writer> Open(const std::filesystem::path& path, cv::Size size, double fps,
                                          const H264Options& options = {});
  ~H264Writer();
  H264Writer(const H264Writer&) = delete;
  H264Writer& operator=(const H264Writer&) = delete;
  // 8-bit BGR at the opened size.
  void Write(const cv::Mat& bgr);
  // Flushes the encoder and writes the file's index; safe to call twice.
  void Close();

 private:
  struct State;
  explicit H264Writer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace arview::video
