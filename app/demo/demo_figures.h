#pragma once
// What a viewer of `arview demo` sees, measured: whether the character is in the picture and
// how large, and a contact sheet of the video.

#include <opencv2/core.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "anim/character.h"
#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::app {

// Points of a character's rest pose placed in the world: its head (the look-at chain's last
// joint, else the highest joint), its root (hips), and every joint (for its extent).
struct CharacterMarkers {
  Eigen::Vector3d head = Eigen::Vector3d::Zero();
  Eigen::Vector3d root = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> joints;
  std::vector<Eigen::Vector3d> extent;  // the skin's bounding box corners
};

// `model_to_world`: the character's model space (asset units) to the world of the poses.
CharacterMarkers MarkersOf(const anim::Character& character, const Eigen::Matrix4d& model_to_world);

struct InViewSummary {
  std::size_t frames = 0;
  std::size_t in_view = 0;                 // head and root both in the picture (and tracked)
  double median_height_fraction = 0;       // of the picture height, frames in view
  double min_height_fraction = 0;
  std::size_t at_least_a_fifth = 0;        // frames in view with height fraction ≥ 0.2
  std::vector<bool> per_frame;
  std::vector<double> height_fraction;     // per frame: the skin's projected height (clipped) / H
};

// One camera pose per frame, std::nullopt where tracking lost the frame (the character is not
// drawn there, so it is not in view).
InViewSummary MeasureInView(const calib::Camera& camera, const std::vector<std::optional<calib::Pose>>& poses,
                            const CharacterMarkers& markers);

// `count` frames spread evenly over `video` (a video file, or a folder of PNG frames as `--out
// <folder>` writes them; first to last), each scaled to `tile_width`,
// tiled `columns` wide, each labelled with its frame number. `include`, a frame of the video,
// takes the place of the evenly spread frame nearest it (the demo's open mouth: a line lasts a
// second, which twelve frames over 22 s can miss). Throws std::runtime_error naming the video
// when it cannot be read.
cv::Mat ContactSheet(const std::filesystem::path& video, int count, int columns, int tile_width,
                     std::optional<int> include = std::nullopt);

// `sheet` with a row of `tile_height` added below: `close_up` cropped about its centre to one
// tile of tile_width x tile_height at its own scale (a still of the face, centred on it), and
// `lines` of text beside it. Throws std::invalid_argument when the close-up is smaller than a
// tile or the sheet is narrower than two.
cv::Mat WithCloseUp(const cv::Mat& sheet, const cv::Mat& close_up, int tile_width, int tile_height,
                    const std::vector<std::string>& lines);

}  // namespace arview::app
