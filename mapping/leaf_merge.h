#pragma once
// The merge of two leaves' models (`arview map --leaf-size`, mapping/leaf_mapping.h), in place of
// COLMAP's model_merger. model_merger fits the similarity between two models to the camera centres
// of the images they share, three at a time: where the shared images stand at one spot (the
// start and end of a room's loop, where the cut between two leaves runs) or along one line (a
// walk through a door) the rotation about that line is not determined, and the merge fails
// ("=> Merge failed") although the leaves agree. Here the similarity is fitted to the shared
// images' 3D points instead (each 2D point that both leaves triangulated is one pair of positions,
// hundreds per image, spread over the scene), in RANSAC over 3 pairs, the inliers judged by the
// angle at the shared image's camera; then the leaves' images and points are joined by
// model_merger's rules (a point whose observations in the shared images are another point's is
// joined to it, one-to-one only; the rest added when 2 observations are left).

#include <string>

#include "base/geometry.h"
#include "mapping/colmap_model.h"

namespace arview::mapping {

struct LeafMergeOptions {
  // A pair of positions agrees when they lie within this angle, in pixels at the camera's focal
  // length, seen from a shared image's camera (the mapper's own filter_max_reproj_error).
  double max_error_px = 4;
  // The fit is taken with at least this many agreeing pairs and this share of all pairs.
  int min_inliers = 30;
  double min_inlier_share = 0.25;
  int ransac_iterations = 500;
};

struct LeafMergeReport {
  int shared_images = 0;       // registered in both models
  int pairs = 0;               // 3D point pairs through the shared images' 2D points
  int inliers = 0;             // pairs that agree under the fit
  Sim3 leaf_to_merged;         // the fit
  int images_added = 0;        // the leaf's images the merged model lacked
  int points_added = 0;        // the leaf's points added as points of their own
  int points_joined = 0;       // the leaf's points joined to a point of the merged model
  std::string Describe() const;  // "19 shared frames, 13514 of 13607 point pairs agree; 142 frames and ... added"
};

// Why a merge is not possible, or empty: fewer than 3 shared images, too few pairs, or no
// similarity that enough pairs agree on.
struct LeafAlignment {
  LeafMergeReport report;
  std::string problem;
};

// The similarity moving `leaf` onto `merged`, fitted to their shared images' 3D points.
// Deterministic (a fixed seed).
LeafAlignment AlignLeaf(const SparseModel& merged, const SparseModel& leaf, const LeafMergeOptions& options = {});

// `leaf` joined into `merged` by an alignment AlignLeaf found (its problem empty), the counts in
// its report; then every observation over options.max_error_px is dropped, and every point left
// with fewer than 2.
void JoinLeaf(SparseModel* merged, const SparseModel& leaf, LeafAlignment* alignment, const LeafMergeOptions& options = {});

}  // namespace arview::mapping
