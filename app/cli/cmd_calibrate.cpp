// arview calibrate: camera intrinsics from photos of a chessboard or ChArUco board, or from a
// live camera (--device) or a recording (--recording) with the views picked as the board is held
// still (app/cli/live_calibration.h); the result's projection uncertainty over the image.

#include "base/image_file.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>

#include <opencv2/imgcodecs.hpp>

#include "app/cli/camera_flags.h"
#include "app/cli/commands.h"
#include "app/cli/live_calibration.h"
#include "app/cli/numeric_flags.h"
#include "base/cancellation.h"
#include "base/progress.h"
#include "calib/calibration.h"
#include "calib/projection_uncertainty.h"
#include "recordings/v4l2_source.h"

namespace arview::app {

namespace {

struct CalibrateArgs {
  std::string images;
  std::string device;
  std::string recording;
  CameraFlags camera_flags;
  bool no_window = false;
  double seconds = 0;
  double distance = 1.0;
  std::string board = "9x6";
  double square = 0.025;
  bool charuco = false;
  double marker = 0;
  std::string dictionary = "DICT_5X5_100";
  std::string out;
  std::string report;
  double reject_factor = 3.0;
};

cv::Size ParseBoard(const std::string& text) {
  static const std::regex kPattern(R"((\d{1,3})x(\d{1,3}))");
  std::smatch m;
  if (!std::regex_match(text, m, kPattern)) {
    throw CommandError("--board '" + text + "' must look like 9x6 (columns x rows)", 2);
  }
  return {std::stoi(m[1]), std::stoi(m[2])};
}

// Fails before the long work starts when the result could not be written.
void CheckWritable(const std::string& path, const char* flag) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw CommandError(std::string(flag) + " " + path + ": folder " + dir.string() + " does not exist");
  if (fs::is_directory(p, ec)) throw CommandError(std::string(flag) + " " + path + ": is a folder, not a file");
  const fs::path probe = dir / (".arview-write-probe-" + std::to_string(::getpid()));
  FILE* f = std::fopen(probe.c_str(), "w");
  if (!f) throw CommandError(std::string(flag) + " " + path + ": folder " + dir.string() + " is not writable");
  std::fclose(f);
  fs::remove(probe, ec);
}

void PrintSummary(const calib::CalibrationResult& r) {
  const calib::Camera& c = r.camera;
  std::printf("\n%-44s %8s %8s %s\n", "view", "corners", "rms px", "");
  for (const calib::ViewReport& v : r.views) {
    const std::string name = std::filesystem::path(v.path).filename().string();
    if (!v.board_found) {
      std::printf("%-44s %8s %8s %s\n", name.c_str(), "-", "-", "no board");
    } else {
      std::printf("%-44s %8d %8.3f %s\n", name.c_str(), v.corners, v.rms, v.rejected ? "rejected (outlier)" : "");
    }
  }
  std::printf("\nRMS reprojection error  %.4f px\n", r.rms);
  std::printf("fx fy                   %.3f %.3f\n", c.fx, c.fy);
  std::printf("cx cy                   %.3f %.3f\n", c.cx, c.cy);
  std::printf("distortion k1 k2 p1 p2 k3  %.5f %.5f %.5f %.5f %.5f\n", c.dist[0], c.dist[1], c.dist[2], c.dist[3], c.dist[4]);
  std::printf("views used / rejected / without board  %d / %d / %d\n", r.views_used, r.views_rejected, r.views_without_board);
  std::printf("image coverage by corners  %.0f%%\n", 100 * r.coverage);
}

// The projection uncertainty's line, and its warning where a region is poor.
calib::ProjectionUncertainty ReportUncertainty(const calib::CalibrationResult& result, double distance) {
  calib::UncertaintyOptions options;
  options.distance_m = distance;
  const calib::ProjectionUncertainty u = calib::EstimateProjectionUncertainty(result, options);
  std::printf("%s\n", u.Summary().c_str());
  if (const std::string warning = u.Warning(); !warning.empty()) std::fprintf(stderr, "warning: %s\n", warning.c_str());
  return u;
}

void WriteResult(const CalibrateArgs& args, const calib::CalibrationResult& result, const calib::Camera& camera) {
  PrintSummary(result);
  const calib::ProjectionUncertainty uncertainty = ReportUncertainty(result, args.distance);
  calib::SaveCamera(camera, args.out);
  std::printf("wrote %s\n", args.out.c_str());
  if (!args.report.empty()) {
    cv::Mat report;
    cv::hconcat(calib::DrawCalibrationReport(result), calib::DrawProjectionUncertainty(uncertainty, result.used_corners),
                report);
    WriteImageAtomically(args.report, report);
    std::printf("wrote %s\n", args.report.c_str());
  }
}

std::string EndingText(const CollectedViews& c) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f s", c.seconds);
  const std::string views = std::to_string(c.views.size()) + " view(s) taken from " + std::to_string(c.frames) +
                            " frames (" + std::to_string(c.frames_with_board) + " with the board) over " + seconds;
  switch (c.ending) {
    case CollectedViews::Ending::kCoverage: return "coverage suffices: " + views;
    case CollectedViews::Ending::kKey: return "c pressed: " + views;
    case CollectedViews::Ending::kSourceEnded: return "the recording ended: " + views;
    case CollectedViews::Ending::kTimeLimit: return "--seconds reached: " + views;
  }
  return views;
}

// The camera set up as `record` sets it up: auto-focus off (the default) where the focus stands,
// since the calibration holds at this focus only.
std::unique_ptr<recordings::V4l2Source> OpenCamera(const CalibrateArgs& args, const CancellationToken& cancel) {
  recordings::V4l2Options options;
  const cv::Size size = *ParseFrameSize(args.camera_flags.size.empty() ? "640x480" : args.camera_flags.size);
  options.width = size.width;
  options.height = size.height;
  ApplyCameraFlags(args.camera_flags, options);
  options.cancel = cancel;
  auto camera = std::make_unique<recordings::V4l2Source>(args.device, options);
  std::cerr << camera->GrantedLine() << "\n";
  for (const std::string& note : camera->notes()) std::cerr << "note: " << note << "\n";
  return camera;
}

// Flags that mean something for some sources only: given with another they are a mistake, not
// ignored.
void RequireFlagsFitTheSource(const CLI::App& cmd, bool images, bool device) {
  for (const char* flag : {"--no-window", "--seconds"}) {
    if (images && cmd.get_option(flag)->count() > 0) throw CommandError(std::string(flag) + " is for --device or --recording", 2);
  }
  for (const char* flag : {"--size", "--fps", "--format", "--focus", "--exposure"}) {
    if (!device && cmd.get_option(flag)->count() > 0) throw CommandError(std::string(flag) + " is for --device (the camera's set-up)", 2);
  }
}

// --device or --recording: views picked from the frames, then calibrated.
void CalibrateFromFrames(const CalibrateArgs& args, const calib::CalibrationOptions& calibration) {
  const ScopedSignalCancellation signals;
  std::unique_ptr<recordings::FrameSource> source;
  recordings::V4l2Source* camera = nullptr;
  if (!args.device.empty()) {
    auto v4l2 = OpenCamera(args, signals.token());
    camera = v4l2.get();
    source = std::move(v4l2);
  } else {
    source = OpenCalibrationRecording(args.recording);
  }
  CalibrationWindowOpener open_window;
  if (!args.no_window) {
    const std::string title = "arview calibrate: " + source->Name();
    open_window = [title](cv::Size size) {
      return video::DisplayWindow::Open(title, size, "calibrate without a window with --no-window");
    };
  }
  LiveCalibrationOptions options;
  options.calibration = calibration;
  options.max_seconds = args.seconds;
  const CollectedViews collected = CollectCalibrationViews(
      *source, options, open_window,
      [](const std::string& line) {
        // At once, as the views are taken: the console is the headless user's window.
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
      },
      signals.token());
  std::printf("%s\n", EndingText(collected).c_str());
  const std::string where = args.device.empty() ? "--recording " + args.recording : args.device;
  if (collected.frames == 0) throw CommandError(where + ": no frame came; nothing was written");
  if (collected.frames_with_board == 0) {
    const bool charuco = calibration.kind == calib::BoardKind::kCharuco;
    throw CommandError(where + ": no " + BoardName(calibration) + " in any of its " + std::to_string(collected.frames) +
                       " frames (" +
                       (charuco ? "--board counts squares, columns x rows; --dictionary " + calibration.charuco_dictionary
                                : std::string("--board counts inner corners, columns x rows")) +
                       "); nothing was written");
  }
  if (static_cast<int>(collected.views.size()) < calibration.min_views) {
    throw CommandError(where + ": only " + std::to_string(collected.views.size()) +
                       " still view(s) of the board; hold it still in more places (at least " +
                       std::to_string(calibration.min_views) + "); nothing was written");
  }
  calib::CalibrationResult result =
      calib::CalibrateDetections(collected.views, collected.labels, collected.image_size, calibration);
  calib::Camera camera_file = result.camera;
  if (camera && camera->focus_held() && camera->focus_position()) {
    camera_file.focus = camera->focus_position();
    std::printf("focus held at %lld while calibrating: camera.yaml says so, and record and run hold it there\n",
                static_cast<long long>(*camera_file.focus));
  } else if (camera) {
    std::fprintf(stderr, "note: %s has no focus position to hold; camera.yaml says none\n", args.device.c_str());
  }
  WriteResult(args, result, camera_file);
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate", "Calibrate a camera from chessboard or ChArUco photos, a live camera or a recording");
  auto* images = cmd->add_option("--images", args->images, "Glob of the board photos, quoted, e.g. \"photos/left*.jpg\"");
  auto* device = cmd->add_option("--device", args->device,
                                 "Calibrate live from this V4L2 camera: views are taken as the board is held still in "
                                 "new places, until the coverage suffices (or c in the window)");
  auto* recording = cmd->add_option("--recording", args->recording,
                                    "Calibrate from a recording folder (arview record) of the board waved in front of "
                                    "the camera, picking views as --device does");
  images->excludes(device)->excludes(recording);
  device->excludes(recording);
  cmd->add_option("--board", args->board, "Chessboard: inner corners, columns x rows. ChArUco: squares, columns x rows")
      ->capture_default_str();
  cmd->add_option("--square", args->square, "Side of one board square in metres")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_flag("--charuco", args->charuco, "The board is a ChArUco board (OpenCV aruco) rather than a chessboard; live, it may be seen in part");
  cmd->add_option("--marker", args->marker, "ChArUco marker side in metres (default: 0.7 x --square)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--dictionary", args->dictionary, "ChArUco marker dictionary")->capture_default_str();
  cmd->add_option("--out", args->out, "Camera file to write (OpenCV FileStorage YAML)")->required();
  cmd->add_option("--report", args->report,
                  "Also write a PNG of corner coverage, per-view errors and the projection uncertainty over the image");
  cmd->add_option("--distance", args->distance, "Working distance in metres at which the projection uncertainty is given")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 1000.0));
  cmd->add_option("--reject-factor", args->reject_factor,
                  "Reject views whose RMS exceeds this many times the median view RMS (and 1 px)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  AddCameraFlags(cmd, args->camera_flags, "--device only; default 640x480, the driver may give the nearest");
  cmd->add_flag("--no-window", args->no_window, "--device, --recording: no window; each view taken is said on the console");
  cmd->add_option("--seconds", args->seconds,
                  "--device, --recording: calibrate with the views taken after this many seconds of footage even if the "
                  "coverage does not suffice yet (0: no limit)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->callback([cmd, args, images, device, recording] {
    if (images->count() + device->count() + recording->count() == 0) {
      throw CommandError("calibrate needs one of --images, --device or --recording", 2);
    }
    RequireFlagsFitTheSource(*cmd, images->count() > 0, device->count() > 0);
    calib::CalibrationOptions options;
    options.board = ParseBoard(args->board);
    options.square_size = args->square;
    options.kind = args->charuco ? calib::BoardKind::kCharuco : calib::BoardKind::kChessboard;
    options.marker_size = args->marker;
    options.charuco_dictionary = args->dictionary;
    options.reject_factor = args->reject_factor;
    CheckWritable(args->out, "--out");
    if (!args->report.empty()) CheckWritable(args->report, "--report");
    if (images->count() == 0) {
      CalibrateFromFrames(*args, options);
      return;
    }
    const std::vector<std::string> files = calib::ExpandImageGlob(args->images);
    Progress progress("detecting corners");
    const calib::CalibrationResult result =
        calib::Calibrate(files, options, [&](int i, int n) { progress.Update(i, n); });
    progress.Finish();
    WriteResult(*args, result, result.camera);
  });
}

}  // namespace arview::app
