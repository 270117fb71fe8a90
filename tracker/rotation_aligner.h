#pragma once
// The camera's rotation between two frames by direct alignment of small blurred images, for the
// frames of a fast turn that the exposure smears beyond what optical flow and SIFT can use (after
// the "small blurry images" of Klein and Murray, "Improving the Agility of Keyframe-Based SLAM",
// ECCV 2008). At 322 deg/s over a 1/60 s exposure the room's frames are smeared by ~50 px at
// 640x480: no corner survives, but shrunk to 80 px wide the picture is smeared by ~6 px and its
// large shapes still show where the camera turned.
//
// Over one frame interval the camera's translation is small against the scene depth (8 mm at
// 0.25 m/s and 30 fps against walls 1-3 m away: under 0.5 px at 80 px wide), so the warp between
// the two frames is the rotation's homography; the rotation is found by Gauss-Newton on the
// intensity difference of the zero-mean, unit-variance images, coarse to fine, with Huber weights
// (a moving object or the borders of what each frame sees should not pull it).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "calib/camera.h"

namespace arview::tracker {

struct RotationAlignerOptions {
  // Longest side of the finest small image, pixels; each coarser level halves it.
  int long_side = 80;
  int levels = 2;
  // Gaussian applied to each small image, its own pixels: smooths the intensity surface so that
  // Gauss-Newton converges from a few pixels away.
  double blur_sigma = 0.75;
  int max_iterations = 30;  // per level
  // The alignment is accepted when the aligned images correlate at least this much
  // (zero-mean normalised cross-correlation over the pixels both frames see), ...
  double min_zncc = 0.85;
  // ... when at least this fraction of the reference's pixels lands in the current image, ...
  double min_overlap = 0.5;
  // ... and when both small images have at least this standard deviation of grey levels (0-255):
  // a blank or black view carries no rotation.
  double min_contrast = 4.0;
};

// One frame shrunk for alignment: per level the normalised image and its camera.
class SmallImage {
 public:
  SmallImage() = default;
  // gray: 8-bit grey image of `camera`'s size (the tracker's working image and camera).
  SmallImage(const cv::Mat& gray, const calib::Camera& camera, const RotationAlignerOptions& options);
  bool empty() const { return levels_.empty(); }
  // Standard deviation of the finest level's grey levels before normalisation.
  double contrast() const { return contrast_; }

  struct Level {
    cv::Mat image;             // CV_32F, zero mean, unit standard deviation (when contrast > 0)
    cv::Mat grad_x, grad_y;    // CV_32F central differences of `image`
    calib::Camera camera;      // the full camera model scaled to this level
    // The largest squared normalised radius the image shows (at its corners): beyond it radial
    // distortion can fold rays from outside the view back into the image.
    double max_radius2 = 0;
  };
  const std::vector<Level>& levels() const { return levels_; }  // finest first

 private:
  std::vector<Level> levels_;
  double contrast_ = 0;
};

struct RotationAlignment {
  bool ok = false;
  // Rotation from the reference camera's frame to the current camera's (R_cur_ref): a point
  // X_ref in the reference camera's coordinates is R_cur_ref · X_ref in the current camera's,
  // up to the translation between them.
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  double zncc = 0;     // of the aligned finest level
  double overlap = 0;  // fraction of the reference's finest pixels seen by the current frame
  int iterations = 0;  // over all levels
  std::string reason;  // why not ok
};

// Aligns `current` to `reference` starting from `initial` (R_cur_ref, e.g. the constant-velocity
// prediction). Both must come from the same camera and options.
RotationAlignment AlignRotation(const SmallImage& reference, const SmallImage& current,
                                const Eigen::Quaterniond& initial, const RotationAlignerOptions& options);

}  // namespace arview::tracker
