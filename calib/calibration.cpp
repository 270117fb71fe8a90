#include "calib/calibration.h"

#include "base/error.h"
#include "base/image_file.h"
#include "base/stats.h"

#include <glob.h>

#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace arview::calib {

std::vector<std::string> ExpandImageGlob(const std::string& pattern) {
  glob_t g{};
  const int rc = ::glob(pattern.c_str(), GLOB_ERR, nullptr, &g);
  std::vector<std::string> files;
  if (rc == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) files.emplace_back(g.gl_pathv[i]);
  }
  globfree(&g);
  if (files.empty()) throw CalibrationError("--images '" + pattern + "' matches no file");
  std::sort(files.begin(), files.end());
  return files;
}

namespace {

cv::Ptr<cv::aruco::Dictionary> CharucoDictionary(const std::string& name) {
  static const std::map<std::string, int> kNames = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},     {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},     {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},   {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},   {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
  };
  const auto it = kNames.find(name);
  if (it == kNames.end()) throw CalibrationError("unknown ChArUco dictionary '" + name + "'");
  return cv::aruco::getPredefinedDictionary(static_cast<cv::aruco::PREDEFINED_DICTIONARY_NAME>(it->second));
}

cv::Ptr<cv::aruco::CharucoBoard> MakeCharucoBoard(const CalibrationOptions& o) {
  const double marker = o.marker_size > 0 ? o.marker_size : 0.7 * o.square_size;
  return cv::aruco::CharucoBoard::create(o.board.width, o.board.height, static_cast<float>(o.square_size),
                                         static_cast<float>(marker), CharucoDictionary(o.charuco_dictionary));
}

bool DetectChessboard(const cv::Mat& gray, const CalibrationOptions& o, BoardDetection* d) {
  std::vector<cv::Point2f> corners = FindChessboardCorners(gray, o.board);
  if (corners.empty()) return false;
  d->image_points = corners;
  d->object_points = ChessboardObjectPoints(o);
  return true;
}

bool DetectCharuco(const cv::Mat& gray, const cv::Ptr<cv::aruco::CharucoBoard>& board, BoardDetection* d) {
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(gray, board->dictionary, marker_corners, marker_ids);
  if (marker_ids.size() < 4) return false;
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  const int n = cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, board, corners, ids);
  // Fewer than 6 corners cannot constrain a homography robustly.
  if (n < 6) return false;
  for (size_t i = 0; i < ids.size(); ++i) {
    d->image_points.push_back(corners[i]);
    d->object_points.push_back(board->chessboardCorners[ids[i]]);
  }
  return true;
}

double ViewRms(const BoardDetection& d, const cv::Mat& K, const cv::Mat& dist, const cv::Mat& rvec, const cv::Mat& tvec) {
  std::vector<cv::Point2f> projected;
  cv::projectPoints(d.object_points, rvec, tvec, K, dist, projected);
  double sum = 0;
  for (size_t i = 0; i < projected.size(); ++i) {
    const cv::Point2f e = projected[i] - d.image_points[i];
    sum += e.dot(e);
  }
  return std::sqrt(sum / projected.size());
}

struct PassResult {
  double rms = 0;
  cv::Mat K, dist;
  std::vector<double> view_rms;
  std::vector<cv::Mat> rvecs, tvecs;
};

PassResult CalibratePass(const std::vector<const BoardDetection*>& views, cv::Size image_size) {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const BoardDetection* d : views) {
    object.push_back(d->object_points);
    image.push_back(d->image_points);
  }
  PassResult r;
  r.rms = cv::calibrateCamera(object, image, image_size, r.K, r.dist, r.rvecs, r.tvecs);
  for (size_t i = 0; i < views.size(); ++i) r.view_rms.push_back(ViewRms(*views[i], r.K, r.dist, r.rvecs[i], r.tvecs[i]));
  return r;
}

}  // namespace

namespace {

// The refinement window must stay inside the corner's four squares: 11 px each way (OpenCV's
// sample) on a board seen small or at a slant, whose squares are 6-8 px tall, pulled corners
// 2-3 px onto their neighbours' edges. Close-up calibration photos keep the full window.
void RefineCorners(const cv::Mat& gray, cv::Size inner_corners, std::vector<cv::Point2f>& corners) {
  double nearest = 1e9;
  for (int row = 0; row < inner_corners.height; ++row) {
    for (int column = 0; column < inner_corners.width; ++column) {
      const cv::Point2f& p = corners[row * inner_corners.width + column];
      if (column + 1 < inner_corners.width) nearest = std::min(nearest, cv::norm(p - corners[row * inner_corners.width + column + 1]));
      if (row + 1 < inner_corners.height) nearest = std::min(nearest, cv::norm(p - corners[(row + 1) * inner_corners.width + column]));
    }
  }
  const int half_window = std::clamp(static_cast<int>(0.45 * nearest), 2, 11);
  cv::cornerSubPix(gray, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.0001));
}

constexpr int kClassicFlags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;

}  // namespace

std::vector<cv::Point2f> FindChessboardCorners(const cv::Mat& gray, cv::Size inner_corners) {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(gray, inner_corners, corners, kClassicFlags)) {
    // A board seen small or at a slant (a map's keyframes: squares of 6-10 px) that the classic
    // detector misses: OpenCV's sector-based detector, whose corners are already sub-pixel.
    corners.clear();
    if (!cv::findChessboardCornersSB(gray, inner_corners, corners, cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) return {};
    return corners;
  }
  RefineCorners(gray, inner_corners, corners);
  return corners;
}

std::vector<cv::Point2f> FindChessboardCornersQuickly(const cv::Mat& gray, cv::Size inner_corners) {
  std::vector<cv::Point2f> corners;
  // Without the adaptive threshold: on the rendered board walk it found as many boards at a
  // sixtieth of the time (docs/calibration.md, "Live calibration").
  const int flags = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  if (!cv::findChessboardCorners(gray, inner_corners, corners, flags)) return {};
  RefineCorners(gray, inner_corners, corners);
  return corners;
}

std::vector<cv::Point3f> ChessboardObjectPoints(const CalibrationOptions& o) {
  std::vector<cv::Point3f> points;
  for (int y = 0; y < o.board.height; ++y) {
    for (int x = 0; x < o.board.width; ++x) {
      points.emplace_back(static_cast<float>(x * o.square_size), static_cast<float>(y * o.square_size), 0.f);
    }
  }
  return points;
}

bool DetectBoard(const cv::Mat& gray, const CalibrationOptions& o, BoardDetection* detection) {
  if (o.kind == BoardKind::kCharuco) return DetectCharuco(gray, MakeCharucoBoard(o), detection);
  return DetectChessboard(gray, o, detection);
}

namespace {

void CheckBoardOptions(const CalibrationOptions& o) {
  if (o.board.width < 2 || o.board.height < 2) throw CalibrationError("board must have at least 2x2 corners");
  if (!(o.square_size > 0)) throw CalibrationError("square size must be positive");
}

}  // namespace

CalibrationResult Calibrate(const std::vector<std::string>& image_paths, const CalibrationOptions& o,
                            const std::function<void(int, int)>& progress) {
  CheckBoardOptions(o);
  cv::Ptr<cv::aruco::CharucoBoard> charuco;
  if (o.kind == BoardKind::kCharuco) charuco = MakeCharucoBoard(o);

  std::vector<BoardDetection> found;
  std::vector<std::string> labels;
  int without_board = 0;
  cv::Size image_size;
  std::string size_source;
  for (size_t i = 0; i < image_paths.size(); ++i) {
    if (progress) progress(static_cast<int>(i) + 1, static_cast<int>(image_paths.size()));
    // ReadImageFile: a cut or damaged photo is one error naming it (cv::imread let libjpeg print
    // "Premature end of JPEG file" and gave the photo with its missing part grey).
    cv::Mat gray;
    try {
      gray = ReadImageFile(image_paths[i], cv::IMREAD_GRAYSCALE);
    } catch (const Error& e) {
      throw CalibrationError(e.what());
    }
    if (image_size.empty()) {
      image_size = gray.size();
      size_source = image_paths[i];
    } else if (gray.size() != image_size) {
      throw CalibrationError(image_paths[i] + ": image is " + std::to_string(gray.cols) + "x" +
                             std::to_string(gray.rows) + " but " + size_source + " is " +
                             std::to_string(image_size.width) + "x" + std::to_string(image_size.height) +
                             "; all calibration images must come from one camera at one size");
    }
    BoardDetection detection;
    const bool board_found = charuco ? DetectCharuco(gray, charuco, &detection) : DetectChessboard(gray, o, &detection);
    if (board_found) {
      found.push_back(std::move(detection));
      labels.push_back(image_paths[i]);
    } else {
      ++without_board;
    }
  }
  CalibrationResult result = CalibrateDetections(found, labels, image_size, o, without_board);
  // The report lists every image in the order given, the ones without a board too.
  std::vector<ViewReport> in_order;
  size_t next_found = 0;
  for (const std::string& path : image_paths) {
    if (next_found < result.views.size() && result.views[next_found].path == path) {
      in_order.push_back(result.views[next_found++]);
    } else {
      ViewReport none;
      none.path = path;
      in_order.push_back(none);
    }
  }
  result.views = std::move(in_order);
  return result;
}

CalibrationResult CalibrateDetections(const std::vector<BoardDetection>& detections,
                                      const std::vector<std::string>& labels, cv::Size image_size,
                                      const CalibrationOptions& o, int images_without_board) {
  CheckBoardOptions(o);
  CalibrationResult result;
  result.views_without_board = images_without_board;
  for (size_t i = 0; i < detections.size(); ++i) {
    ViewReport view;
    view.path = i < labels.size() ? labels[i] : "view " + std::to_string(i + 1);
    view.board_found = true;
    view.corners = static_cast<int>(detections[i].image_points.size());
    result.views.push_back(view);
  }
  std::vector<size_t> used(detections.size());
  for (size_t i = 0; i < used.size(); ++i) used[i] = i;
  const int images = static_cast<int>(detections.size()) + images_without_board;
  auto too_few = [&](const std::string& why) {
    return CalibrationError("only " + std::to_string(used.size()) + " usable view(s) of " + std::to_string(images) +
                            " image(s) " + why + "; at least " + std::to_string(o.min_views) + " are needed");
  };
  if (static_cast<int>(used.size()) < o.min_views) {
    throw too_few(used.empty() ? "(no board found: check --board, which counts inner corners)" : "");
  }

  auto run = [&](const std::vector<size_t>& indices) {
    std::vector<const BoardDetection*> views;
    for (size_t i : indices) views.push_back(&detections[i]);
    return CalibratePass(views, image_size);
  };
  PassResult pass = run(used);
  const double threshold = std::max(o.reject_factor * Median(pass.view_rms), o.reject_floor_px);
  std::vector<size_t> kept;
  for (size_t k = 0; k < used.size(); ++k) {
    result.views[used[k]].rms = pass.view_rms[k];
    if (pass.view_rms[k] > threshold) {
      result.views[used[k]].rejected = true;
      ++result.views_rejected;
    } else {
      kept.push_back(used[k]);
    }
  }
  if (kept.size() != used.size()) {
    used = kept;
    if (static_cast<int>(used.size()) < o.min_views) throw too_few("after rejecting outlier views");
    pass = run(used);
    for (size_t k = 0; k < used.size(); ++k) result.views[used[k]].rms = pass.view_rms[k];
  }

  Camera& c = result.camera;
  c.width = image_size.width;
  c.height = image_size.height;
  c.fx = pass.K.at<double>(0, 0);
  c.fy = pass.K.at<double>(1, 1);
  c.cx = pass.K.at<double>(0, 2);
  c.cy = pass.K.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) c.dist[i] = pass.dist.at<double>(i);
  c.Validate("calibration result");
  result.rms = pass.rms;
  result.views_used = static_cast<int>(used.size());
  for (size_t k = 0; k < used.size(); ++k) {
    result.used_views.push_back(detections[used[k]]);
    result.rvecs.emplace_back(pass.rvecs[k]);
    result.tvecs.emplace_back(pass.tvecs[k]);
  }

  const int gx = o.coverage_grid, gy = std::max(1, o.coverage_grid * 3 / 4);
  std::vector<char> cells(gx * gy, 0);
  for (size_t i : used) {
    result.used_corners.push_back(detections[i].image_points);
    for (const cv::Point2f& p : detections[i].image_points) {
      const int cxi = std::clamp(static_cast<int>(p.x / image_size.width * gx), 0, gx - 1);
      const int cyi = std::clamp(static_cast<int>(p.y / image_size.height * gy), 0, gy - 1);
      cells[cyi * gx + cxi] = 1;
    }
  }
  result.coverage = static_cast<double>(std::count(cells.begin(), cells.end(), 1)) / cells.size();
  return result;
}

cv::Mat DrawCalibrationReport(const CalibrationResult& r) {
  const int w = r.camera.width, h = r.camera.height;
  cv::Mat left(h, w, CV_8UC3, cv::Scalar(30, 30, 30));
  for (size_t v = 0; v < r.used_corners.size(); ++v) {
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(static_cast<int>(180.0 * v / std::max<size_t>(1, r.used_corners.size())), 220, 255));
    cv::Mat bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    for (const cv::Point2f& p : r.used_corners[v]) cv::circle(left, p, 3, cv::Scalar(c[0], c[1], c[2]), cv::FILLED, cv::LINE_AA);
  }
  cv::putText(left, cv::format("corner coverage %.0f%%", 100 * r.coverage), {10, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
              {255, 255, 255}, 1, cv::LINE_AA);

  cv::Mat right(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_rms = 0.5;
  for (const ViewReport& v : r.views) max_rms = std::max(max_rms, v.rms);
  const int n = static_cast<int>(r.views.size());
  const int margin = 40, plot_h = h - 2 * margin;
  const double bar_w = static_cast<double>(w - 2 * margin) / std::max(1, n);
  for (int i = 0; i < n; ++i) {
    const ViewReport& v = r.views[i];
    const int x0 = margin + static_cast<int>(i * bar_w) + 1, x1 = margin + static_cast<int>((i + 1) * bar_w) - 1;
    if (!v.board_found) {
      cv::putText(right, "x", {x0, h - margin - 4}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {128, 128, 128});
      continue;
    }
    const int top = h - margin - static_cast<int>(plot_h * v.rms / max_rms);
    cv::rectangle(right, {x0, top}, {x1, h - margin}, v.rejected ? cv::Scalar(40, 40, 220) : cv::Scalar(180, 120, 40),
                  cv::FILLED);
  }
  const int mean_y = h - margin - static_cast<int>(plot_h * r.rms / max_rms);
  cv::line(right, {margin, mean_y}, {w - margin, mean_y}, {0, 160, 0}, 1, cv::LINE_AA);
  cv::putText(right, cv::format("per-view RMS (px), overall %.3f; red = rejected, x = no board", r.rms), {10, 25},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(right, cv::format("%.2f", max_rms), {2, margin + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0});
  cv::Mat out;
  cv::hconcat(left, right, out);
  return out;
}

cv::Mat DrawCharucoBoard(const CalibrationOptions& options, int pixels_per_square, int margin_px) {
  const auto board = MakeCharucoBoard(options);
  cv::Mat image;
  const cv::Size squares(options.board.width * pixels_per_square, options.board.height * pixels_per_square);
  if (margin_px < 0) {
    board->draw(squares, image, pixels_per_square / 2);
  } else {
    board->draw(squares + cv::Size(2 * margin_px, 2 * margin_px), image, margin_px);
  }
  return image;
}

}  // namespace arview::calib
