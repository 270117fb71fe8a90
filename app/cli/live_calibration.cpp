#include "app/cli/live_calibration.h"

#include <algorithm>
#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "app/cli/commands.h"
#include "app/cli/window_panel.h"

namespace arview::app {

namespace {

constexpr int kPanelWidth = 260;

std::vector<cv::Point> Rounded(const std::vector<cv::Point2f>& points) { return {points.begin(), points.end()}; }


// What to do to fill the emptiest bar.
std::string Advice(const std::vector<calib::CoverageBar>& bars) {
  const auto emptiest = std::min_element(bars.begin(), bars.end(), [](const auto& a, const auto& b) {
    return a.progress < b.progress;
  });
  if (emptiest->name == "X") return "move it left and right";
  if (emptiest->name == "Y") return "move it up and down";
  if (emptiest->name == "size") return "bring it nearer and take it farther";
  return "tilt it";
}

std::string StatusOf(calib::ViewSelector::Decision decision, const calib::ViewSelector& selector,
                     const calib::CalibrationOptions& board) {
  using Decision = calib::ViewSelector::Decision;
  switch (decision) {
    case Decision::kNoBoard:
      return board.kind == calib::BoardKind::kCharuco ? "no board: show the " + BoardName(board) + " (part of it will do)"
                                                      : "no board: show the whole " + BoardName(board);
    case Decision::kMoving: return "hold the board still";
    case Decision::kKnown: return "seen already: " + Advice(selector.Bars());
    case Decision::kTaken: return "view " + std::to_string(selector.taken().size()) + " taken";
  }
  return "";
}

std::string BarsText(const std::vector<calib::CoverageBar>& bars) {
  std::string text;
  for (const calib::CoverageBar& bar : bars) {
    text += (text.empty() ? "" : ", ") + bar.name + " " + std::to_string(static_cast<int>(100 * bar.progress + 0.5)) + "%";
  }
  return text;
}

// Events since the last frame: true when c asks to calibrate now. q, Escape or closing the
// window stops without calibrating.
bool CalibrateAsked(video::DisplayWindow& window) {
  bool asked = false;
  for (const video::InputEvent& event : window.Poll()) {
    if (event.type == video::InputEvent::Type::kClose ||
        (event.type == video::InputEvent::Type::kKey && (event.key == "q" || event.key == "Escape"))) {
      throw CommandError("calibration stopped in the window before it calibrated; nothing was written");
    }
    if (event.type == video::InputEvent::Type::kKey && event.key == "c") asked = true;
  }
  return asked;
}

}  // namespace

calib::BoardDetection DetectLive(const cv::Mat& gray, const calib::CalibrationOptions& board) {
  calib::BoardDetection found;
  if (board.kind == calib::BoardKind::kCharuco) {
    if (!calib::DetectBoard(gray, board, &found)) found = {};
    return found;
  }
  found.image_points = calib::FindChessboardCornersQuickly(gray, board.board);
  if (!found.image_points.empty()) found.object_points = calib::ChessboardObjectPoints(board);
  return found;
}

std::string BoardName(const calib::CalibrationOptions& board) {
  const std::string size = std::to_string(board.board.width) + "x" + std::to_string(board.board.height);
  return size + (board.kind == calib::BoardKind::kCharuco ? " ChArUco board" : " chessboard");
}

cv::Size CalibrationWindowSize(cv::Size frame_size) {
  return {frame_size.width + kPanelWidth, std::max(frame_size.height, 360)};
}

cv::Mat DrawCalibrationWindow(const cv::Mat& frame, const calib::BoardDetection& found,
                              const calib::CalibrationOptions& board, const calib::ViewSelector& selector,
                              const std::string& status) {
  cv::Mat picture(CalibrationWindowSize(frame.size()), CV_8UC3, cv::Scalar(40, 40, 40));
  cv::Mat shown = picture(cv::Rect({0, 0}, frame.size()));
  frame.copyTo(shown);
  for (const auto& outline : selector.taken_outlines()) {
    cv::polylines(shown, Rounded(outline), true, {200, 160, 60}, 1, cv::LINE_AA);
  }
  const std::vector<cv::Point2f>& corners = found.image_points;
  if (board.kind == calib::BoardKind::kCharuco && !corners.empty()) {
    // The part of the board found now, outlined as a view of it would be taken, and its corners
    // ringed in black: small green dots alone were lost on the board's black and white squares.
    const std::vector<cv::Point2f> seen = calib::PartialBoardOutline(corners, found.object_points);
    if (!seen.empty()) cv::polylines(shown, Rounded(seen), true, {60, 220, 60}, 2, cv::LINE_AA);
    for (const cv::Point2f& p : corners) {
      cv::circle(shown, p, 5, {0, 0, 0}, cv::FILLED, cv::LINE_AA);
      cv::circle(shown, p, 3, {60, 220, 60}, cv::FILLED, cv::LINE_AA);
    }
  } else if (corners.size() == static_cast<size_t>(board.board.area())) {
    cv::drawChessboardCorners(shown, board.board, corners, true);
  }

  const int left = frame.cols + 16, bar_width = kPanelWidth - 32;
  const auto text = [&](const std::string& line, int y, double scale = 0.55, cv::Scalar colour = {235, 235, 235}) {
    cv::putText(picture, line, {left, y}, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
  };
  text("coverage", 28, 0.65);
  int y = 50;
  for (const calib::CoverageBar& bar : selector.Bars()) {
    text(bar.name, y + 14);
    const cv::Rect outline(left + 50, y, bar_width - 50, 18);
    DrawBar(picture, outline, bar.progress, bar.progress >= 1.0 ? cv::Scalar(60, 200, 60) : cv::Scalar(40, 150, 240));
    y += 34;
  }
  text("views taken: " + std::to_string(selector.taken().size()), y + 12);
  text(selector.Sufficient() ? "enough: calibrating" : "c: calibrate now, q: stop", y + 40, 0.5, {180, 180, 180});
  int status_y = y + 76;
  for (const std::string& line : WrapWords(status, 26)) {
    text(line, status_y, 0.5, {120, 230, 255});
    status_y += 20;
  }
  return picture;
}

CollectedViews CollectCalibrationViews(recordings::FrameSource& source, const LiveCalibrationOptions& options,
                                       const CalibrationWindowOpener& open_window, const CalibrationLog& log,
                                       const CancellationToken& cancel) {
  const calib::CalibrationOptions& board = options.calibration;
  const bool charuco = board.kind == calib::BoardKind::kCharuco;
  CollectedViews collected;
  std::unique_ptr<calib::ViewSelector> selector;
  std::unique_ptr<video::DisplayWindow> window;
  double first_time = 0;
  recordings::Frame frame;
  cv::Mat gray;
  while (true) {
    cancel.ThrowIfCancelled("calibration stopped before it calibrated; nothing was written");
    if (!source.Next(frame)) {
      collected.ending = CollectedViews::Ending::kSourceEnded;
      break;
    }
    if (!selector) {
      collected.image_size = frame.image.size();
      selector = std::make_unique<calib::ViewSelector>(board.board, collected.image_size, options.selection);
      first_time = frame.timestamp;
      if (open_window) window = open_window(CalibrationWindowSize(collected.image_size));
    } else if (frame.image.size() != collected.image_size) {
      throw calib::CalibrationError(source.Name() + ": frame " + std::to_string(frame.index) + " is " +
                                    std::to_string(frame.image.cols) + "x" + std::to_string(frame.image.rows) +
                                    " but the first was " + std::to_string(collected.image_size.width) + "x" +
                                    std::to_string(collected.image_size.height) + "; a calibration is of one size");
    }
    ++collected.frames;
    collected.seconds = frame.timestamp - first_time;
    cv::cvtColor(frame.image, gray, cv::COLOR_BGR2GRAY);
    const calib::BoardDetection found = DetectLive(gray, board);
    if (!found.image_points.empty()) ++collected.frames_with_board;
    const calib::ViewSelector::Decision decision =
        charuco ? selector->OfferPartial(found.image_points, found.object_points, frame.timestamp)
                : selector->Offer(found.image_points, frame.timestamp);
    if (decision == calib::ViewSelector::Decision::kTaken) {
      collected.views.push_back(found);
      char label[64];
      std::snprintf(label, sizeof label, "frame %lld at %.2f s", static_cast<long long>(frame.index), collected.seconds);
      collected.labels.emplace_back(label);
      if (log) log("view " + std::to_string(collected.views.size()) + " taken (" + label + "); coverage " + BarsText(selector->Bars()));
    }
    bool asked = false;
    if (window) {
      window->Show(DrawCalibrationWindow(frame.image, found, board, *selector, StatusOf(decision, *selector, board)));
      asked = CalibrateAsked(*window);
    }
    if (selector->Sufficient()) {
      collected.ending = CollectedViews::Ending::kCoverage;
      break;
    }
    if (asked) {
      if (static_cast<int>(collected.views.size()) >= options.calibration.min_views) {
        collected.ending = CollectedViews::Ending::kKey;
        break;
      }
      if (log) log("c: not yet, " + std::to_string(collected.views.size()) + " view(s) taken of the " +
                   std::to_string(options.calibration.min_views) + " a calibration needs at least");
    }
    if (options.max_seconds > 0 && collected.seconds >= options.max_seconds) {
      collected.ending = CollectedViews::Ending::kTimeLimit;
      break;
    }
  }
  if (selector) collected.bars = selector->Bars();
  return collected;
}

std::unique_ptr<recordings::FrameSource> OpenCalibrationRecording(const std::filesystem::path& folder) {
  const std::filesystem::path list = folder / "frames.txt";
  std::error_code error;
  if (!std::filesystem::is_regular_file(list, error)) {
    throw recordings::RecordingError("--recording " + folder.string() + ": no frames.txt there (a recording folder " +
                                     "of arview record)");
  }
  recordings::Recording recording;
  recording.root = folder;
  recording.frames = recordings::ReadFrameList(list);
  if (recording.frames.empty()) throw recordings::RecordingError(list.string() + ": lists no frames");
  // The replay holds every frame to its camera's size; with no camera yet, the first frame's.
  cv::Size size;
  if (recording.IsVideo()) {
    cv::VideoCapture video(recording.FramePath(0).string());
    if (!video.isOpened()) throw recordings::RecordingError(recording.FramePath(0).string() + ": cannot be opened as a video");
    size = {static_cast<int>(video.get(cv::CAP_PROP_FRAME_WIDTH)), static_cast<int>(video.get(cv::CAP_PROP_FRAME_HEIGHT))};
  } else {
    size = recording.ReadImage(0).size();
  }
  recording.camera = calib::Camera::Pinhole(size.width, size.height, size.width, size.width, (size.width - 1) / 2.0,
                                            (size.height - 1) / 2.0);
  return std::make_unique<recordings::RecordingSource>(std::move(recording));
}

}  // namespace arview::app
