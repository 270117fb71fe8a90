#pragma once
// Registered images whose pose fits their own observations far worse than the model's other
// images, posed again from those observations with the points held. COLMAP's bundle adjustment
// can leave one frame in a local minimum: on the rendered venue's room-3, where the walk turns in
// place, frame 476 fitted its 645 points at a median of 1.76 px where its neighbours fitted
// theirs at 0.19 px, and its centre stood 52 mm off the truth with theirs at 2 mm; two rounds of
// adjustment did not move it (docs/mapping.md, "A frame the adjustment left behind").

#include <filesystem>
#include <string>
#include <vector>

#include "base/option_check.h"
#include "mapping/colmap_model.h"

namespace arview::mapping {

struct OutlyingPoseOptions {
  // An image is posed again when the median of its observations' reprojection errors is over
  // both this (pixels) and `over_model_median` times the median of the images' medians.
  double min_median_px = 0.4;
  double over_model_median = 2.0;
  int min_observations = 30;       // fewer: left as it is (too few to pose it again)
  double ransac_px = 2.0;          // RANSAC's inlier threshold, pixels
  // The new pose is kept when its median is at most this share of the old one's.
  double keep_below_share = 0.5;

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

struct RePosedImage {
  std::string name;
  int observations = 0;
  double median_before_px = 0;
  double median_after_px = 0;
  bool kept = false;  // the new pose replaced the old one
};

// The images of `model` found outlying, each posed again (OpenCV's P3P in RANSAC, then
// Levenberg-Marquardt on the inliers) and its pose replaced when it fits its observations at
// keep_below_share of its old median or better.
std::vector<RePosedImage> RePoseOutlyingImages(SparseModel* model, const OutlyingPoseOptions& options = {});

// RePoseOutlyingImages on the model in `sparse_dir`, written back (images.bin) when a pose was
// replaced. Throws MapError as ReadSparseModel and WriteSparseModel do.
std::vector<RePosedImage> RePoseOutlyingImagesIn(const std::filesystem::path& sparse_dir,
                                                 const OutlyingPoseOptions& options = {});

// "room-3/frames/000476.png: its 645 observations at a median of 1.76 px, posed again: 0.19 px".
std::string Describe(const RePosedImage& image);

}  // namespace arview::mapping
