#pragma once
// `arview calibrate --device` and `--recording`: views of a board picked from a stream of frames
// (calib/board_views.h chooses them), shown as they are taken in a window with the corners
// drawn, the coverage bars (X, Y, size, skew) and the views taken, until the coverage suffices,
// the user presses c, or the stream ends. The calibration itself is calib's.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/cancellation.h"
#include "calib/board_views.h"
#include "calib/calibration.h"
#include "recordings/frame_source.h"
#include "video/window.h"

namespace arview::app {

struct LiveCalibrationOptions {
  calib::CalibrationOptions calibration;
  calib::ViewSelectionOptions selection;
  // Stop looking after this many seconds of footage (0: until the coverage suffices, c, or the end).
  double max_seconds = 0;
};

// How the views were collected.
struct CollectedViews {
  std::vector<calib::BoardDetection> views;
  std::vector<std::string> labels;  // "frame 123 at 4.10 s"
  cv::Size image_size;
  int frames = 0, frames_with_board = 0;
  double seconds = 0;  // footage from the first frame to the last looked at
  enum class Ending { kCoverage, kKey, kSourceEnded, kTimeLimit } ending = Ending::kSourceEnded;
  std::vector<calib::CoverageBar> bars;
};

// What the command prints as the views come: one line each (a view taken, the coverage after it).
using CalibrationLog = std::function<void(const std::string&)>;

// Opens the window for frames of the size given (CalibrationWindowSize of it).
using CalibrationWindowOpener = std::function<std::unique_ptr<video::DisplayWindow>(cv::Size window_size)>;

// Reads `source` until the coverage suffices (or c in the window, the time limit, the stream's
// end, or cancellation, which throws CancelledError). `open_window` (empty: no window) is called
// at the first frame. Throws CalibrationError when a frame's size changes, CommandError when the
// window is closed (q, Escape).
CollectedViews CollectCalibrationViews(recordings::FrameSource& source, const LiveCalibrationOptions& options,
                                       const CalibrationWindowOpener& open_window, const CalibrationLog& log,
                                       const CancellationToken& cancel);

// The window's picture: the frame with the board's corners found (a chessboard's coloured, a
// ChArUco board's as dots ringed in black inside the green outline of the part found) and the
// outlines of the views taken, faint; on the right the coverage bars, the number of views and
// `status`.
cv::Mat DrawCalibrationWindow(const cv::Mat& frame, const calib::BoardDetection& found,
                              const calib::CalibrationOptions& board, const calib::ViewSelector& selector,
                              const std::string& status);

// The board of a live frame: a chessboard whole (the quick detector), a ChArUco board in part (at
// least 6 corners, each with its place on the board); empty when none.
calib::BoardDetection DetectLive(const cv::Mat& gray, const calib::CalibrationOptions& board);
// "9x6 chessboard", "10x7 ChArUco board".
std::string BoardName(const calib::CalibrationOptions& board);
// The window's size for frames of `frame_size`.
cv::Size CalibrationWindowSize(cv::Size frame_size);

// A recording folder's frames for calibration: frames.txt and its pictures (or one video file),
// no camera.yaml needed (the camera is what is being calibrated). Throws RecordingError naming the
// folder or file.
std::unique_ptr<recordings::FrameSource> OpenCalibrationRecording(const std::filesystem::path& folder);

}  // namespace arview::app
