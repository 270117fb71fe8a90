#pragma once
// What a head-mounted display needs of the composed picture: each eye's view placed in its half
// of the panel at the angular size the camera saw it (so that the room keeps its scale through
// the lens), centred on the eye's lens, and pre-distorted with the inverse of the lens's radial
// magnification (barrel against the lens's pincushion), so that straight lines look straight.
//
// A single camera gives one view of the room: both eyes get the same video (biocular). The
// character is drawn into it once by default; with --stereo-character each eye gets its own
// render, ±ipd/2 apart (right only on a metric map). docs/app.md, "Headsets", says why.

#include <filesystem>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/camera.h"

namespace arview::render {

// An HMD profile file (docs/examples/hmd-cardboard.yaml):
//   name: cardboard-v2
//   panel: [2560, 1440]       # pixels, both eyes side by side
//   eye_fov_deg: 90           # horizontal field of view of one eye's half through its lens
//   lens_centre: [0.5, 0.5]   # the left eye's lens centre, fraction of its half; the right mirrored
//   distortion: [0.34, 0.55]  # k1, k2 of the lens: a panel point at tangent radius r is seen at
//                             # r (1 + k1 r² + k2 r⁴)
struct HmdProfile {
  std::string name;
  cv::Size panel;
  double eye_fov_deg = 90;
  Eigen::Vector2d lens_centre{0.5, 0.5};
  double k1 = 0, k2 = 0;
};

// Reads and checks a profile; a bad one is a RenderError naming the file and the field.
HmdProfile LoadHmdProfile(const std::filesystem::path& file);

// Builds each eye's sampling map once; Present is then one remap per eye.
class HmdPresenter {
 public:
  // `view`: the pinhole camera of the composed views (the renderer's output camera).
  HmdPresenter(const HmdProfile& profile, const calib::Camera& view);

  // The panel picture: `left` and `right` (views of `view`'s size, BGR) each in its eye's half.
  cv::Mat Present(const cv::Mat& left, const cv::Mat& right) const;
  // Where the pixel `panel_px` of eye 0 (left) or 1 (right), in that eye's half, samples its view.
  Eigen::Vector2d SourceOf(int eye, const Eigen::Vector2d& panel_px) const;
  // The eye's lens centre and focal length in its half's pixels.
  Eigen::Vector2d LensCentre(int eye) const;
  double EyeFocalPx() const { return eye_focal_px_; }
  cv::Size panel() const { return profile_.panel; }
  const HmdProfile& profile() const { return profile_; }

 private:
  HmdProfile profile_;
  calib::Camera view_;
  double eye_focal_px_ = 0;
  cv::Mat map_x_[2], map_y_[2];  // per eye, CV_32FC1 of the half's size
};

}  // namespace arview::render
