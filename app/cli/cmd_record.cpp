// arview record --device /dev/video0 --out <recording> [--size 640x480] [--fps N] [--seconds N]
//               [--format auto|yuyv|mjpeg] [--focus lock|auto|keep|N] [--exposure auto|lock|N]
//               [--camera camera.yaml] [--force] [--window]

#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/cli/camera_flags.h"
#include "app/cli/commands.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/record_window.h"
#include "base/cancellation.h"
#include "recordings/capture_guidance.h"
#include "recordings/recorder.h"
#include "recordings/v4l2_source.h"
#include "video/window.h"

namespace arview::app {

namespace {

struct RecordArgs {
  std::string device = "/dev/video0";
  std::string out;
  CameraFlags camera_flags;
  double seconds = 0;
  std::string camera;
  bool force = false;
  bool window = false;
};

constexpr const char* kDefaultSize = "640x480";

// "; 3 frames lost (2 dropped by the driver, 1 corrupt)": said even when none were, since a
// recording with holes must not pass for a complete one.
std::string LostText(const recordings::SourceCounts& counts, int out_of_order) {
  const int64_t lost = counts.driver_dropped + counts.corrupt_skipped + counts.stale_skipped + out_of_order;
  std::string text = "; " + std::to_string(lost) + " frame" + (lost == 1 ? "" : "s") + " lost";
  if (lost == 0) return text;
  std::string parts;
  auto add = [&](int64_t n, const char* what) {
    if (n > 0) parts += (parts.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(counts.driver_dropped, "dropped by the driver");
  add(counts.corrupt_skipped, "corrupt");
  add(counts.stale_skipped, "waiting behind newer ones");
  add(out_of_order, "out of order");
  return text + " (" + parts + ")";
}

// Events since the last frame: q, Escape or closing the window ends the recording (what was
// recorded stays, as with Ctrl-C).
bool StopAsked(video::DisplayWindow& window) {
  for (const video::InputEvent& event : window.Poll()) {
    if (event.type == video::InputEvent::Type::kClose ||
        (event.type == video::InputEvent::Type::kKey && (event.key == "q" || event.key == "Escape"))) {
      return true;
    }
  }
  return false;
}

// The end's verdict: whether the recording is likely to map, and why not.
void PrintGuidance(const recordings::CaptureGuidance& guidance) {
  std::cout << "capture guidance: " << guidance.Summary().Line() << "\n";
}

void RunRecord(const RecordArgs& args) {
  const std::string size_text = args.camera_flags.size.empty() ? kDefaultSize : args.camera_flags.size;
  const cv::Size size = *ParseFrameSize(size_text);  // checked by --size's validator
  std::optional<calib::Camera> camera;
  if (!args.camera.empty()) {
    camera = calib::LoadCamera(args.camera);
  }
  // Ctrl-C (or SIGTERM) is how a recording without --seconds ends: the frames written so far
  // are a valid recording. With --seconds, an early stop says so and exits non-zero.
  const ScopedSignalCancellation signals;
  recordings::V4l2Options options;
  options.width = size.width;
  options.height = size.height;
  ApplyCameraFlags(args.camera_flags, options);
  if (camera) options.focus = SessionFocus(args.camera_flags, *camera);
  // A recording keeps every frame the buffers hold, in order: the newest-only reading of a live
  // session would leave holes whenever a PNG takes longer to write than a frame period.
  options.newest_only = false;
  options.cancel = signals.token();
  recordings::V4l2Source source(args.device, options);
  std::cerr << source.GrantedLine() << "\n";
  for (const std::string& note : source.notes()) std::cerr << "note: " << note << "\n";
  if (source.size() != size) {
    std::cerr << "note: " << args.device << " gives " << source.size().width << "x" << source.size().height
              << " instead of " << size_text << "\n";
  }
  if (camera && camera->Size() != source.size()) {
    throw CommandError(args.camera + ": camera is " + std::to_string(camera->width) + "x" +
                       std::to_string(camera->height) + " but " + args.device + " delivers " +
                       std::to_string(source.size().width) + "x" + std::to_string(source.size().height));
  }
  if (camera) {
    if (const std::string mismatch = FocusMismatch(source, *camera, args.camera); !mismatch.empty())
      std::cerr << "warning: " << mismatch << "\n";
    // The recording says at which focus its frames were taken, so that a map built from it
    // and the sessions run on that map hold the camera there too.
    if (!camera->focus && source.focus_held() && source.focus_position()) {
      camera->focus = source.focus_position();
      std::cerr << "note: " << args.camera << " does not say at which focus it was calibrated; the recording's "
                << "camera.yaml says the focus it was made at, " << *camera->focus << "\n";
    }
  }
  recordings::RecordingWriter writer(args.out, camera, args.force);
  std::cerr << "recording into " << args.out << (args.seconds > 0 ? "" : "; Ctrl-C stops") << "\n";
  bool progress_shown = false;  // the progress line is redrawn in place: ended before any other line
  const recordings::CaptureGuidanceOptions guidance_options;
  recordings::CaptureGuidance guidance(guidance_options);
  std::unique_ptr<video::DisplayWindow> window;
  if (args.window) {
    window = video::DisplayWindow::Open("arview record " + args.out, RecordWindowSize(source.size()),
                                        "record without a window: leave out --window");
  }
  auto progress = [&](const recordings::Frame& frame, const recordings::RecordStats& s) {
    guidance.Add(frame.image, frame.timestamp);
    for (const recordings::GuidanceNote& note : guidance.NewNotes()) {
      std::fprintf(stderr, "%snote: %.1f s: %s\n", progress_shown ? "\n" : "", note.time, note.text.c_str());
      progress_shown = false;
    }
    if (window) {
      window->Show(DrawRecordWindow(frame.image, guidance, guidance_options, {s.seconds, s.frames}));
      if (StopAsked(*window)) signals.token().Cancel(0);
    }
    const recordings::SourceCounts c = source.Counts();
    std::fprintf(stderr, "\r%8.1f s  %6d frames  %5.1f fps  %5lld lost", s.seconds, s.frames, s.fps,
                 static_cast<long long>(c.driver_dropped + c.corrupt_skipped + c.stale_skipped + s.skipped));
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
                       " frames recorded before stay a valid recording in " + args.out +
                       LostText(source.Counts(), 0));
  }
  if (progress_shown) std::fprintf(stderr, "\n");
  if (writer.RemoveIfEmpty()) {
    signals.token().ThrowIfCancelled("stopped before the first frame; nothing was recorded");
    throw CommandError("stopped before the first frame; nothing was recorded");
  }
  const bool stopped_in_window = signals.token().IsCancelled() && signals.token().Signal() == 0;
  if (args.seconds > 0 && signals.token().IsCancelled() && !stopped_in_window) {
    PrintGuidance(guidance);
    std::ostringstream what;
    what << "stopped after " << stats.seconds << " of " << args.seconds << " s; the " << stats.frames
         << " frames recorded stay a valid recording in " << args.out;
    signals.token().ThrowIfCancelled(what.str());
  }
  std::cout << "recorded " << stats.frames << " frames over " << stats.seconds << " s into " << args.out
            << LostText(source.Counts(), stats.skipped) << (stopped_in_window ? " (stopped in the window)" : "") << "\n";
  PrintGuidance(guidance);
  if (!camera) {
    std::cout << "note: no --camera given: put a camera.yaml (arview calibrate) into " << args.out
              << " before mapping or tracking\n";
  }
}

}  // namespace

void AddRecordCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("record", "Record a V4L2 camera into a recording folder");
  auto args = std::make_shared<RecordArgs>();
  cmd->add_option("--device", args->device, "V4L2 capture device")->capture_default_str();
  cmd->add_option("--out", args->out, "Recording folder to create")->required();
  AddCameraFlags(cmd, args->camera_flags, std::string("default ") + kDefaultSize + "; the driver may give the nearest");
  cmd->add_option("--seconds", args->seconds, "Stop after this many seconds (0: until Ctrl-C)")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  cmd->add_option("--camera", args->camera, "camera.yaml to store with the recording (its size must match)");
  cmd->add_flag("--force", args->force, "Replace a recording already in --out");
  cmd->add_flag("--window", args->window,
                "Show the camera's picture with the capture guidance (too fast, too few features, too little "
                "parallax, exposure, views so far); q stops");
  cmd->callback([args] { RunRecord(*args); });
}

}  // namespace arview::app
