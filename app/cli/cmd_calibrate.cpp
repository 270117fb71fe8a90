// arview calibrate: camera intrinsics from photos of a chessboard or ChArUco board.

#include "base/image_file.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>

#include <opencv2/imgcodecs.hpp>

#include "app/cli/commands.h"
#include "base/progress.h"
#include "calib/calibration.h"

namespace arview::app {

namespace {

struct CalibrateArgs {
  std::string images;
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

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand("calibrate", "Calibrate a camera from chessboard or ChArUco photos");
  cmd->add_option("--images", args->images, "Glob of the board photos, quoted, e.g. \"photos/left*.jpg\"")->required();
  cmd->add_option("--board", args->board, "Chessboard: inner corners, columns x rows. ChArUco: squares, columns x rows")
      ->capture_default_str();
  cmd->add_option("--square", args->square, "Side of one board square in metres")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_flag("--charuco", args->charuco, "The board is a ChArUco board (OpenCV aruco) rather than a chessboard");
  cmd->add_option("--marker", args->marker, "ChArUco marker side in metres (default: 0.7 x --square)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--dictionary", args->dictionary, "ChArUco marker dictionary")->capture_default_str();
  cmd->add_option("--out", args->out, "Camera file to write (OpenCV FileStorage YAML)")->required();
  cmd->add_option("--report", args->report, "Also write a PNG of corner coverage and per-view errors");
  cmd->add_option("--reject-factor", args->reject_factor,
                  "Reject views whose RMS exceeds this many times the median view RMS (and 1 px)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  cmd->callback([args] {
    calib::CalibrationOptions options;
    options.board = ParseBoard(args->board);
    options.square_size = args->square;
    options.kind = args->charuco ? calib::BoardKind::kCharuco : calib::BoardKind::kChessboard;
    options.marker_size = args->marker;
    options.charuco_dictionary = args->dictionary;
    options.reject_factor = args->reject_factor;
    CheckWritable(args->out, "--out");
    if (!args->report.empty()) CheckWritable(args->report, "--report");
    const std::vector<std::string> files = calib::ExpandImageGlob(args->images);
    Progress progress("detecting corners");
    const calib::CalibrationResult result =
        calib::Calibrate(files, options, [&](int i, int n) { progress.Update(i, n); });
    progress.Finish();
    PrintSummary(result);
    calib::SaveCamera(result.camera, args->out);
    std::printf("wrote %s\n", args->out.c_str());
    if (!args->report.empty()) {
      WriteImageAtomically(args->report, calib::DrawCalibrationReport(result));
      std::printf("wrote %s\n", args->report.c_str());
    }
  });
}

}  // namespace arview::app
