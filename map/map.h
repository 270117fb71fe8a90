#pragma once
// The Map the tracker loads: COLMAP's sparse model and feature descriptors, in memory, in the
// map's world frame. This library (map/) is the contract between mapping/ (which builds it from
// COLMAP's output) and tracker/ (which loads and reads it); it needs neither COLMAP nor SQLite.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"

#include "base/error.h"
#include "base/geometry.h"

namespace arview::map {

struct MapError : Error {
  using Error::Error;
};

struct MapPoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
  double reprojection_error = 0;     // COLMAP's mean error of the track, pixels
  std::uint32_t first_descriptor = 0;  // rows [first, first + count) of Map::descriptors
  std::uint32_t descriptor_count = 0;
};

// One 2D-3D correspondence of a keyframe, in OpenCV pixel convention (COLMAP's +0.5 removed).
struct KeyframeObservation {
  std::uint32_t point = 0;  // index into Map::points
  Eigen::Vector2f pixel = Eigen::Vector2f::Zero();
  std::uint32_t descriptor = 0;  // row of Map::descriptors holding this observation's SIFT
};

struct Keyframe {
  std::uint32_t colmap_image_id = 0;
  std::string name;          // frame path relative to the recording
  int frame_index = -1;      // index into the recording's frames.txt
  double timestamp = 0;
  calib::Pose pose;          // world → camera
  std::vector<KeyframeObservation> observations;
  int room = -1;             // index into Map::rooms; -1: no room (one recording's map)
};

// Where the map's scale and "up" come from (docs/mapping.md, "Metric scale and up").
enum class ScaleSource : std::uint8_t {
  kNone = 0,          // COLMAP's own frame: arbitrary units, arbitrary orientation
  kBoard = 1,         // a chessboard of known square size seen in the keyframes
  kKnownDistance = 2, // the distance between two points the user gave
  kCameraHeight = 3,  // an estimate: the cameras' height over the floor taken as a typical one
};

// The map's frame. With a scale source the map is in metres; with z_up, +z points away from the
// floor (or the board lying on it) and z = 0 is that floor. mapping/ transforms COLMAP's model,
// the keyframes and the points into this frame; `from_colmap` says how, for whoever compares the
// map with COLMAP's own output.
struct MapFrame {
  ScaleSource scale_source = ScaleSource::kNone;
  bool z_up = false;
  double scale_error = 0;   // the scale's likely relative error (0.01: 1 %), as estimated
  std::string how;          // one line: what the scale and up were taken from, with its figures
  Sim3 from_colmap;         // COLMAP's mapper frame → this frame

  bool metric() const { return scale_source != ScaleSource::kNone; }
};

const char* ToString(ScaleSource source);  // "none", "board", "known distance", "camera height"

struct Map {
  calib::Camera camera;  // OpenCV convention
  MapFrame frame;        // COLMAP's frame unless mapping/ made it metric
  std::vector<Keyframe> keyframes;
  std::vector<MapPoint> points;
  // One row per track element: uint8 SIFT in COLMAP's convention (L1-root, ×512, clamp 255).
  cv::Mat descriptors;                      // N x 128, CV_8U
  std::vector<std::uint32_t> descriptor_point;  // row → index into points
  // Filled by mapping/: row → index into keyframes (the keyframe whose keypoint gave the row).
  std::vector<std::uint32_t> descriptor_keyframe;
  // A venue's rooms (its recordings, docs/mapping.md "A venue of several recordings"), named as in
  // its venue.json; each keyframe names its own. Empty for the map of one recording.
  std::vector<std::string> rooms;
};

// The room of the keyframe whose centre is nearest `centre` (map units), or -1 when the map has
// no rooms: where a camera localized there stands.
int RoomAt(const Map& map, const Eigen::Vector3d& centre);

// Reading and writing maps, and what `arview map info` prints: map/map_file.h.

}  // namespace arview::map
