#pragma once
// An H.264 file written with FFmpeg's libraries directly (libx264 through libavcodec, muxed by
// libavformat), for the video sink: OpenCV's FFmpeg writer (4.6) opens x264 with its default
// preset, medium, and passes it no options. Medium cost 16 ms of CPU per 640x480 frame —
// trellis quantisation most of it — as much as rendering the frame, on the two cores that
// tracking and rendering share. Superfast at the same quality setting costs about 3 ms
// (docs/render.md, "Output sinks"). One encoder thread: the sink stage's time is then the
// encoder's whole cost, and it does not take CPU from the other stages behind their back.

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

namespace arview::video {

// An AAC audio track beside the video (FFmpeg's native `aac` encoder, AAC-LC), from mono int16
// clips placed on the video's timeline: the character's lines in `replay` and `demo`.
struct AudioTrackOptions {
  int sample_rate = 16000;   // of the samples given to WriteAudio (speech's); AAC's rate when it has it
  int bit_rate = 48000;      // bits per second of AAC
  // Audio this far behind the last frame written stays open, so that a clip that arrives a
  // little after its time is still mixed in; older audio is encoded and written.
  double holdback_seconds = 1.0;
  // A clip may start at most this far after the audio already written (a bound on the memory
  // held for the gap).
  double max_gap_seconds = 600.0;
};

struct H264Options {
  std::string preset = "superfast";  // x264's speed/compression trade-off
  int crf = 23;                      // x264's constant-quality setting (its default)
  std::optional<AudioTrackOptions> audio;  // none: a video-only file, as before
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
  // 8-bit BGR at the opened size. Frame n is shown at n / fps.
  void Write(const cv::Mat& bgr);
  // Mono samples at the track's rate whose first is heard at first_sample / sample_rate seconds
  // after the first frame. Clips that overlap are summed (saturating), gaps are silence, audio
  // goes on past the last frame to the end of the last clip. Samples that fall before 0, or in
  // audio already written (more than holdback_seconds behind the last frame), are dropped and
  // counted (AudioSamplesDropped). Throws VideoError naming the file when it has no audio track,
  // is closed, or the clip starts more than max_gap_seconds after the audio written.
  void WriteAudio(std::int64_t first_sample, std::span<const std::int16_t> samples);
  std::int64_t AudioSamplesDropped() const;
  // Flushes the encoder and writes the file's index; safe to call twice.
  void Close();

 private:
  struct State;
  explicit H264Writer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace arview::video
