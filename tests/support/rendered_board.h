#pragma once
// A chessboard waved in front of a camera as a person calibrating does, rendered with exact
// intrinsics and distortion: the board is carried to a place in the image, near or far, tilted,
// held there (with a hand's slight sway) for a moment, then carried to the next. Each frame is
// rendered at twice the size and averaged down (edges anti-aliased as a lens and sensor blur
// them), moving boards are smeared over the exposure (several renders along the motion
// averaged), and sensor noise is added. What `arview calibrate --device` (through the emulated
// camera) and `--recording` must recover: tests/calibrate_live_test.cpp.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibration.h"
#include "calib/camera.h"

namespace arview::testing {

struct BoardWalk {
  // The truth: a webcam-like lens with strong barrel distortion.
  calib::Camera camera = [] {
    calib::Camera c = calib::Camera::Pinhole(640, 480, 520.0, 523.0, 317.3, 244.6);
    c.dist = {-0.28, 0.09, 0.0008, -0.0005, 0};
    return c;
  }();
  cv::Size board{9, 6};        // inner corners
  double square = 0.025;       // metres
  double fps = 15;
  double hold_seconds = 0.8;   // still at each place
  double move_seconds = 1.0;   // carried between places
  double exposure = 1.0 / 30;  // the shutter's open time: the smear of a moving board
  double noise_sigma = 2.0;    // grey levels
  unsigned seed = 5;
  // A ChArUco board of (board + 1) squares (DICT_5X5_100, markers 0.7 of a square) instead of the
  // chessboard: the same squares, its inner corners where the chessboard's are.
  bool charuco = false;
};

// The walk of a ChArUco board (tests/calibrate_live_test.cpp): twice the chessboard's size, so
// that it fills more of the image at each place; fewer frames (10 a second, shorter holds and
// moves); and places at the image's corners where part of the board leaves the image, which only
// ChArUco's partial views can use.
inline BoardWalk CharucoWalk() {
  BoardWalk walk;
  walk.charuco = true;
  // 50 mm squares (an A3 print): a marker's 5x5 bits are 3 px wide at 0.8 m, where 25 mm ones
  // (1.6 px) were found in part or not at all.
  walk.square = 0.05;
  walk.fps = 10;
  walk.hold_seconds = 0.6;
  walk.move_seconds = 0.8;
  walk.seed = 6;
  return walk;
}

// The calibration options of the walk's board.
inline calib::CalibrationOptions BoardOptions(const BoardWalk& walk) {
  calib::CalibrationOptions o;
  o.kind = walk.charuco ? calib::BoardKind::kCharuco : calib::BoardKind::kChessboard;
  o.board = walk.charuco ? walk.board + cv::Size(1, 1) : walk.board;
  o.square_size = walk.square;
  return o;
}

// Where the board is held: its centre's image position (fractions of the width and height), its
// distance, and its turn (Rodrigues, radians; zero faces the camera).
struct BoardPlace {
  double u, v, depth;
  Eigen::Vector3d turn;
  bool partly_out = false;  // the centre where (u, v) says, though part of the board leaves the image
};

// Places across the image at half a metre, tilted about alternating axes; near, filling most of
// the image (turned a little: more would take a corner out of it); then across it again, far.
inline std::vector<BoardPlace> BoardPlaces() {
  std::vector<BoardPlace> places;
  const double tilt = 0.6;  // 34°
  const std::vector<Eigen::Vector3d> turns = {{tilt, 0, 0}, {0, tilt, 0}, {-tilt, 0, 0.1}, {0, -tilt, -0.1},
                                              {0, 0, 0},    {tilt * 0.7, tilt * 0.7, 0}};
  int k = 0;
  const auto across = [&](double depth) {
    for (double v : {0.2, 0.5, 0.8}) {
      for (double u : {0.15, 0.5, 0.85}) places.push_back({u, v, depth, turns[k++ % turns.size()]});
    }
  };
  across(0.5);
  places.push_back({0.5, 0.5, 0.25, {0.15, 0, 0}});
  places.push_back({0.5, 0.5, 0.27, {0, -0.2, 0}});
  across(0.8);
  return places;
}

// ChArUco's walk: across the image at half a metre, near, at the image's four corners with the
// board half out of it, and the far corners; the board's centre where each place says, however
// much of it leaves the image.
inline std::vector<BoardPlace> CharucoPlaces() {
  const std::vector<BoardPlace> all = BoardPlaces();
  std::vector<BoardPlace> places(all.begin(), all.begin() + 11);  // across at 0.5 m, then the two near
  const double tilt = 0.5;
  places.push_back({0.02, 0.03, 0.4, {tilt, 0, 0}, true});
  places.push_back({0.98, 0.03, 0.4, {0, tilt, 0}, true});
  places.push_back({0.98, 0.97, 0.4, {-tilt, 0, 0}, true});
  places.push_back({0.02, 0.97, 0.4, {0, -tilt, 0}, true});
  for (int i : {11, 13, 17, 19}) places.push_back(all[i]);  // far, at the corners
  // Nowhere pulled in to keep the whole board in the image: held where a person holds it.
  for (BoardPlace& place : places) place.partly_out = true;
  return places;
}

inline std::vector<BoardPlace> WalkPlaces(const BoardWalk& walk) { return walk.charuco ? CharucoPlaces() : BoardPlaces(); }

// The board's pose in the camera (x_camera = R x_board + t) for a place: the board's centre on
// the ray through (u, v), clamped so that the whole board stays in the image.
inline Eigen::Isometry3d PoseOfPlace(const BoardWalk& walk, const BoardPlace& place) {
  const double width = (walk.board.width + 1) * walk.square, height = (walk.board.height + 1) * walk.square;
  const double half_u = 0.5 * width * walk.camera.fx / place.depth / walk.camera.width + 0.04;
  const double half_v = 0.5 * height * walk.camera.fy / place.depth / walk.camera.height + 0.04;
  const double u = place.partly_out ? place.u : std::clamp(place.u, std::min(0.5, half_u), std::max(0.5, 1 - half_u));
  const double v = place.partly_out ? place.v : std::clamp(place.v, std::min(0.5, half_v), std::max(0.5, 1 - half_v));
  const double x = (u * walk.camera.width - walk.camera.cx) / walk.camera.fx * place.depth;
  const double y = (v * walk.camera.height - walk.camera.cy) / walk.camera.fy * place.depth;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const double angle = place.turn.norm();
  if (angle > 0) pose.linear() = Eigen::AngleAxisd(angle, place.turn / angle).toRotationMatrix();
  // The board's origin is its first inner corner; its centre sits on the ray.
  const Eigen::Vector3d centre_on_board((walk.board.width - 1) * walk.square / 2, (walk.board.height - 1) * walk.square / 2, 0);
  pose.translation() = Eigen::Vector3d(x, y, place.depth) - pose.linear() * centre_on_board;
  return pose;
}

// Between two poses: the rotation slerped, the translation interpolated; s in [0, 1].
inline Eigen::Isometry3d Between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(a.linear()).slerp(s, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  pose.translation() = (1 - s) * a.translation() + s * b.translation();
  return pose;
}

// The board's pose at time t: held, then carried with a smooth start and stop (a person's
// reach), the hold swaying by half a millimetre.
inline Eigen::Isometry3d PoseAt(const BoardWalk& walk, const std::vector<Eigen::Isometry3d>& places, double t) {
  const double leg = walk.hold_seconds + walk.move_seconds;
  const int i = std::min(static_cast<int>(t / leg), static_cast<int>(places.size()) - 1);
  const double within = t - i * leg;
  Eigen::Isometry3d pose = places[i];
  if (within > walk.hold_seconds && i + 1 < static_cast<int>(places.size())) {
    const double s = (within - walk.hold_seconds) / walk.move_seconds;
    pose = Between(places[i], places[i + 1], 0.5 - 0.5 * std::cos(M_PI * s));
  }
  pose.translation() += Eigen::Vector3d(0.0005 * std::sin(2 * M_PI * 0.9 * t), 0.0004 * std::sin(2 * M_PI * 1.3 * t), 0);
  return pose;
}

inline double BoardWalkSeconds(const BoardWalk& walk) {
  return WalkPlaces(walk).size() * (walk.hold_seconds + walk.move_seconds) - walk.move_seconds;
}

// Renders the walk's camera seeing the board at its poses. Keeps the per-pixel rays of the
// doubled image (undistorted once: the lens does not change).
class BoardRenderer {
 public:
  explicit BoardRenderer(const BoardWalk& walk) : walk_(walk) {
    const cv::Size big(2 * walk.camera.width, 2 * walk.camera.height);
    rays_.create(big, CV_64FC2);
    for (int row = 0; row < big.height; ++row) {
      for (int column = 0; column < big.width; ++column) {
        // The doubled image's pixel centre in the camera's pixels (OpenCV's convention).
        const Eigen::Vector2d pixel((column + 0.5) / 2 - 0.5, (row + 0.5) / 2 - 0.5);
        const Eigen::Vector2d ray = walk.camera.PixelToNormalized(pixel);
        rays_.at<cv::Vec2d>(row, column) = {ray.x(), ray.y()};
      }
    }
    // The board's picture: squares of kTexel px, one white square's margin all round.
    const int columns = walk.board.width + 1, rows = walk.board.height + 1;
    if (walk.charuco) {
      // Printed black (25) on white (235), as the chessboard.
      calib::DrawCharucoBoard(BoardOptions(walk), kTexel, kTexel).convertTo(texture_, CV_32F, 210.0 / 255, 25);
      return;
    }
    texture_ = cv::Mat((rows + 2) * kTexel, (columns + 2) * kTexel, CV_32F, cv::Scalar(235));
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < columns; ++c) {
        if ((r + c) % 2 == 0) texture_(cv::Rect((c + 1) * kTexel, (r + 1) * kTexel, kTexel, kTexel)).setTo(25);
      }
    }
  }

  // One exposure: the board at each of `poses` (along its motion), averaged; 8-bit grey.
  cv::Mat Render(const std::vector<Eigen::Isometry3d>& poses) const {
    cv::Mat sum(rays_.size(), CV_32F, cv::Scalar(0));
    cv::Mat map_x(rays_.size(), CV_32F), map_y(rays_.size(), CV_32F), sampled;
    for (const Eigen::Isometry3d& pose : poses) {
      // A ray (x, y, 1) meets the board's plane where H^-1 (x, y, 1) is, H = [r1 r2 t].
      Eigen::Matrix3d h;
      h << pose.linear().col(0), pose.linear().col(1), pose.translation();
      const Eigen::Matrix3d to_board = h.inverse();
      // The board's first inner corner is texel ((1 + 1) * kTexel) from the texture's corner.
      const double scale = kTexel / walk_.square, offset = 2 * kTexel - 0.5;
      for (int row = 0; row < rays_.rows; ++row) {
        const cv::Vec2d* ray = rays_.ptr<cv::Vec2d>(row);
        float* mx = map_x.ptr<float>(row);
        float* my = map_y.ptr<float>(row);
        for (int column = 0; column < rays_.cols; ++column) {
          const Eigen::Vector3d b = to_board * Eigen::Vector3d(ray[column][0], ray[column][1], 1);
          const bool behind = b.z() <= 0;
          mx[column] = behind ? -1e6f : static_cast<float>(b.x() / b.z() * scale + offset);
          my[column] = behind ? -1e6f : static_cast<float>(b.y() / b.z() * scale + offset);
        }
      }
      cv::remap(texture_, sampled, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(110));
      sum += sampled;
    }
    sum /= static_cast<double>(poses.size());
    cv::Mat small;
    cv::resize(sum, small, walk_.camera.Size(), 0, 0, cv::INTER_AREA);
    return small;
  }

 private:
  static constexpr int kTexel = 32;
  BoardWalk walk_;
  cv::Mat rays_;     // CV_64FC2: each doubled pixel's normalised, undistorted ray
  cv::Mat texture_;  // CV_32F grey
};

// Writes the walk as a recording folder: frames/NNNNNN.jpg (quality 95), frames.txt at `fps`,
// and the truth as truth.yaml (not camera.yaml: a calibration recording has none). Returns the
// number of frames.
inline int WriteBoardWalk(const std::filesystem::path& folder, const BoardWalk& walk = {}) {
  namespace fs = std::filesystem;
  fs::create_directories(folder / "frames");
  std::vector<Eigen::Isometry3d> places;
  for (const BoardPlace& place : WalkPlaces(walk)) places.push_back(PoseOfPlace(walk, place));
  const BoardRenderer renderer(walk);
  std::mt19937 random(walk.seed);
  const int frames = static_cast<int>(BoardWalkSeconds(walk) * walk.fps);
  std::ofstream list(folder / "frames.txt");
  cv::Mat noise(walk.camera.Size(), CV_32F);
  for (int i = 0; i < frames; ++i) {
    const double t = i / walk.fps;
    // Several renders over the exposure where the board moves more than a pixel's worth in it.
    const Eigen::Isometry3d start = PoseAt(walk, places, t), end = PoseAt(walk, places, t + walk.exposure);
    const double travel = (end.translation() - start.translation()).norm() +
                          Eigen::AngleAxisd(start.linear().transpose() * end.linear()).angle() * 0.2;
    const int samples = std::clamp(static_cast<int>(travel / 0.0005), 1, 8);
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k < samples; ++k) poses.push_back(PoseAt(walk, places, t + walk.exposure * (k + 0.5) / samples));
    cv::Mat grey = renderer.Render(poses);
    cv::theRNG().state = random();
    cv::randn(noise, 0, walk.noise_sigma);
    grey += noise;
    cv::Mat picture;
    grey.convertTo(picture, CV_8U);
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.jpg", i);
    cv::imwrite((folder / name).string(), picture, {cv::IMWRITE_JPEG_QUALITY, 95});
    list << cv::format("%.6f %s\n", t, name);
  }
  calib::SaveCamera(walk.camera, folder / "truth.yaml");
  return frames;
}

}  // namespace arview::testing
