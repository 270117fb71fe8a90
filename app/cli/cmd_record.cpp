// arview record --device /dev/video0 --out <recording> [--size 640x480] [--seconds N]
//               [--format auto|yuyv|mjpeg] [--camera camera.yaml] [--force]

#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/numeric_flags.h"
#include "base/cancellation.h"
#include "recordings/recorder.h"
#include "recordings/v4l2_source.h"

namespace arview::app {

namespace {

struct RecordArgs {
  std::string device = "/dev/video0";
  std::string out;
  std::string size = "640x480";
  double seconds = 0;
  std::string format = "auto";
  std::string camera;
  bool force = false;
};

void RunRecord(const RecordArgs& args) {
  const cv::Size size = *ParseFrameSize(args.size);  // checked by --size's validator
  std::optional<calib::Camera> camera;
  if (!args.camera.empty()) {
    try {
      camera = calib::LoadCamera(args.camera);
    } catch (const calib::CameraError& e) {
      throw CommandError(e.what());
    }
  }
  // Ctrl-C (or SIGTERM) is how a recording without --seconds ends: the frames written so far
  // are a valid recording. With --seconds, an early stop says so and exits non-zero.
  const ScopedSignalCancellation signals;
  recordings::V4l2Options options;
  options.width = size.width;
  options.height = size.height;
  options.format = args.format;
  options.cancel = signals.token();
  try {
    recordings::V4l2Source source(args.device, options);
    if (source.size() != size) {
      std::cerr << "note: " << args.device << " gives " << source.size().width << "x" << source.size().height
                << " instead of " << args.size << "\n";
    }
    if (camera && camera->Size() != source.size()) {
      throw CommandError(args.camera + ": camera is " + std::to_string(camera->width) + "x" +
                         std::to_string(camera->height) + " but " + args.device + " delivers " +
                         std::to_string(source.size().width) + "x" + std::to_string(source.size().height));
    }
    recordings::RecordingWriter writer(args.out, camera, args.force);
    std::cerr << "recording " << args.device << " (" << source.CardName() << ", " << source.FormatName() << " "
              << source.size().width << "x" << source.size().height << ") into " << args.out
              << (args.seconds > 0 ? "" : "; Ctrl-C stops") << "\n";
    bool progress_shown = false;  // the progress line is redrawn in place: ended before any other line
    auto progress = [&](const recordings::RecordStats& s) {
      std::fprintf(stderr, "\r%8.1f s  %6d frames  %5.1f fps", s.seconds, s.frames, s.fps);
      std::fflush(stderr);
      progress_shown = true;
    };
    recordings::RecordStats stats;
    try {
      stats = recordings::RecordFrames(source, writer, args.seconds, signals.token(), progress);
    } catch (const recordings::RecordingError& e) {
      // The camera failing (SourceError) or the disk (a frame or frames.txt that cannot be
      // written): either way the frames before stay a valid recording, or none is left.
      if (progress_shown) std::fprintf(stderr, "\n");
      if (writer.RemoveIfEmpty()) throw CommandError(std::string(e.what()) + "; nothing was recorded");
      throw CommandError(std::string(e.what()) + "; the " + std::to_string(writer.frame_count()) +
                         " frames recorded before stay a valid recording in " + args.out);
    }
    if (progress_shown) std::fprintf(stderr, "\n");
    if (writer.RemoveIfEmpty()) {
      signals.token().ThrowIfCancelled("stopped before the first frame; nothing was recorded");
      throw CommandError("stopped before the first frame; nothing was recorded");
    }
    if (args.seconds > 0 && signals.token().IsCancelled()) {
      std::ostringstream what;
      what << "stopped after " << stats.seconds << " of " << args.seconds << " s; the " << stats.frames
           << " frames recorded stay a valid recording in " << args.out;
      signals.token().ThrowIfCancelled(what.str());
    }
    std::cout << "recorded " << stats.frames << " frames over " << stats.seconds << " s into " << args.out;
    if (source.skipped_frames() + stats.skipped > 0) {
      std::cout << " (" << source.skipped_frames() + stats.skipped << " corrupt or out-of-order frames skipped)";
    }
    std::cout << "\n";
    if (!camera) {
      std::cout << "note: no --camera given: put a camera.yaml (arview calibrate) into " << args.out
                << " before mapping or tracking\n";
    }
  } catch (const recordings::RecordingError& e) {  // SourceError included
    throw CommandError(e.what());
  }
}

}  // namespace

void AddRecordCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("record", "Record a V4L2 camera into a recording folder");
  auto args = std::make_shared<RecordArgs>();
  cmd->add_option("--device", args->device, "V4L2 capture device")->capture_default_str();
  cmd->add_option("--out", args->out, "Recording folder to create")->required();
  cmd->add_option("--size", args->size, "Requested frame size WIDTHxHEIGHT (the driver may choose the nearest)")
      ->capture_default_str()
      ->check(FrameSizeCheck({16, 16}, {7680, 4320}));
  cmd->add_option("--seconds", args->seconds, "Stop after this many seconds (0: until Ctrl-C)")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  cmd->add_option("--format", args->format, "Pixel format to ask the camera for")
      ->check(CLI::IsMember({"auto", "yuyv", "mjpeg"}))
      ->capture_default_str();
  cmd->add_option("--camera", args->camera, "camera.yaml to store with the recording (its size must match)");
  cmd->add_flag("--force", args->force, "Replace a recording already in --out");
  cmd->callback([args] { RunRecord(*args); });
}

}  // namespace arview::app
