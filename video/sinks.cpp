#include "video/sinks.h"

#include "base/error.h"
#include "base/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <atomic>
#include <cstdlib>
#include <filesystem>

#include "video/h264_writer.h"
#include "video/video_error.h"
#include "video/window.h"

namespace arview::video {
namespace {

namespace fs = std::filesystem;

std::string SizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

void CheckFrame(const cv::Mat& frame, cv::Size size, const std::string& target) {
  if (frame.size() != size || frame.type() != CV_8UC3) {
    throw VideoError(target + ": frame is " + SizeText(frame.size()) + " type " + std::to_string(frame.type()) +
                      ", the sink was opened for " + SizeText(size) + " BGR");
  }
}

class WindowSink final : public FrameSink {
 public:
  WindowSink(std::string title, cv::Size size, const WindowPlacement& placement) : title_(std::move(title)), size_(size) {
    if (!HasDisplay()) {
      throw VideoError("window output needs a display, and DISPLAY is not set; "
                                "write to a file instead (e.g. --out out.mp4)");
    }
    window_ = DisplayWindow::Open(title_, size, "write to a file instead (e.g. --out out.mp4)", placement);
    // Kept for after Close: the session describes its output once the window is gone.
    const std::string placed = window_->PlacementText();
    description_ = "window \"" + title_ + "\" (" + window_->PresentMethod() + (placed.empty() ? "" : ", " + placed) + ")";
  }
  ~WindowSink() override { Close(); }
  void Write(const cv::Mat& bgr) override {
    CheckFrame(bgr, size_, "window");
    window_->Show(bgr);
    PumpEvents();
  }
  void PumpEvents() override {
    if (!window_) return;
    for (const InputEvent& e : window_->Poll()) {
      const bool quit_key = e.type == InputEvent::Type::kKey && (e.key == "Escape" || e.key == "q");
      if (quit_key || e.type == InputEvent::Type::kClose) stop_ = true;
      else if (e.type == InputEvent::Type::kKey && key_handler_) key_handler_(e.key);
    }
  }
  void SetStatus(const std::string& status) override {
    // A title change is a round trip to the server: only when the text changes.
    const std::string title = status.empty() ? title_ : title_ + " | " + status;
    if (!window_ || title == shown_title_) return;
    window_->SetTitle(title);
    shown_title_ = title;
  }
  void Close() override { window_.reset(); }
  bool StopRequested() const override { return stop_; }
  std::string Describe() const override { return description_; }

 private:
  std::string title_, shown_title_, description_;
  cv::Size size_;
  std::unique_ptr<DisplayWindow> window_;
  std::atomic<bool> stop_{false};  // set on the writing thread, read by the capture thread
};

class VideoSink final : public FrameSink {
 public:
  VideoSink(const fs::path& path, cv::Size size, double fps, const std::optional<AudioTrackOptions>& audio)
      : path_(path), size_(size) {
    if (!(fps > 0 && fps <= 1000)) throw VideoError(path.string() + ": frame rate must be in (0, 1000]");
    if (path.has_parent_path() && !fs::is_directory(path.parent_path())) {
      throw VideoError(path.string() + ": folder " + path.parent_path().string() + " does not exist");
    }
    // H.264 through libx264 at a fast preset (video/h264_writer.h says why not OpenCV's writer);
    // without libx264, OpenCV's writer: H.264 if its FFmpeg has another encoder for it, else
    // MPEG-4 part 2, which every FFmpeg build has.
    H264Options options;
    options.audio = audio;
    h264_ = H264Writer::Open(path, size, fps, options);
    if (h264_) {
      codec_ = "H.264, libx264 " + options.preset + (audio ? ", AAC" : "");
      has_audio_ = audio.has_value();
      return;
    }
    if (audio) throw VideoError(path.string() + ": no libx264 in this FFmpeg for a video with sound (OpenCV's writer has no audio)");
    for (const char* codec : {"avc1", "mp4v"}) {
      writer_.open(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc(codec[0], codec[1], codec[2], codec[3]), fps,
                   size, true);
      if (writer_.isOpened()) {
        codec_ = codec;
        break;
      }
    }
    if (!writer_.isOpened()) throw VideoError(path.string() + ": OpenCV's FFmpeg writer cannot open this file");
  }
  ~VideoSink() override {
    h264_.reset();
    writer_.release();
  }
  void Write(const cv::Mat& bgr) override {
    CheckFrame(bgr, size_, path_.string());
    if (h264_) h264_->Write(bgr);
    else writer_.write(bgr);
  }
  void Close() override {
    if (h264_) h264_->Close();
    writer_.release();
    std::error_code ec;
    if (!closed_ && (!fs::exists(path_, ec) || fs::file_size(path_, ec) == 0)) {
      closed_ = true;
      throw VideoError(path_.string() + ": the video file was not written");
    }
    closed_ = true;
  }
  std::string Describe() const override { return path_.string() + " (" + codec_ + ")"; }
  bool HasAudio() const override { return h264_ && has_audio_; }
  void WriteAudio(std::int64_t first_sample, std::span<const std::int16_t> samples) override {
    if (!HasAudio()) FrameSink::WriteAudio(first_sample, samples);
    else h264_->WriteAudio(first_sample, samples);
  }
  std::int64_t AudioSamplesDropped() const override { return h264_ ? h264_->AudioSamplesDropped() : 0; }

 private:
  fs::path path_;
  cv::Size size_;
  bool has_audio_ = false;
  std::unique_ptr<H264Writer> h264_;
  cv::VideoWriter writer_;
  std::string codec_;
  bool closed_ = false;
};

class PngSequenceSink final : public FrameSink {
 public:
  PngSequenceSink(const fs::path& folder, cv::Size size) : folder_(folder), size_(size) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec || !fs::is_directory(folder)) throw VideoError(folder.string() + ": cannot create the PNG folder");
  }
  void Write(const cv::Mat& bgr) override {
    CheckFrame(bgr, size_, folder_.string());
    const fs::path file = PngFrameFile(folder_, index_++);
    WriteImageAtomically(file, bgr, {cv::IMWRITE_PNG_COMPRESSION, 1});
  }
  void Close() override {}
  std::string Describe() const override { return folder_.string() + "/NNNNNN.png"; }

 private:
  fs::path folder_;
  cv::Size size_;
  int index_ = 0;
};

// Counts the frames and keeps none (`--out null`: soak runs and timing without an encoder).
class NullSink final : public FrameSink {
 public:
  explicit NullSink(cv::Size size) : size_(size) {}
  void Write(const cv::Mat& bgr) override {
    CheckFrame(bgr, size_, "null");
    ++frames_;
  }
  void Close() override {}
  std::string Describe() const override { return "null (" + std::to_string(frames_) + " frames discarded)"; }

 private:
  cv::Size size_;
  long frames_ = 0;
};

}  // namespace

bool IsWindowTarget(const std::string& target) { return target == "window" || target.rfind("window:", 0) == 0; }

bool HasDisplay() {
  const char* value = std::getenv("DISPLAY");
  return value != nullptr && *value != '\0';
}

void FrameSink::WriteAudio(std::int64_t, std::span<const std::int16_t>) {
  throw VideoError(Describe() + ": has no audio track");
}

std::filesystem::path PngFrameFile(const std::filesystem::path& folder, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.png", index);
  return folder / name;
}

std::unique_ptr<FrameSink> OpenSink(const std::string& target, cv::Size frame_size, double fps,
                                    const WindowPlacement& window, const std::optional<AudioTrackOptions>& audio) {
  if (frame_size.width <= 0 || frame_size.height <= 0) throw VideoError("sink: frame size must be positive");
  if (IsWindowTarget(target)) {
    return std::make_unique<WindowSink>(target.size() > 7 ? target.substr(7) : "arview", frame_size, window);
  }
  if (target == "null") return std::make_unique<NullSink>(frame_size);
  if (target.empty()) throw VideoError("sink: no output given");
  const fs::path path(target);
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".mp4" || ext == ".avi" || ext == ".mkv") return std::make_unique<VideoSink>(path, frame_size, fps, audio);
  if (target.back() == '/' || ext.empty() || fs::is_directory(path)) {
    return std::make_unique<PngSequenceSink>(path, frame_size);
  }
  throw VideoError(target + ": unknown output (expected window, null, a .mp4/.avi/.mkv file, or a folder for PNGs)");
}

}  // namespace arview::video
