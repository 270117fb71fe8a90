#include "mapping/leaf_merge.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "base/error.h"

namespace arview::mapping {

namespace {

// One 2D point of a shared image triangulated by both models: its position in each, and the
// shared image's camera centre in the merged model (where the agreement is judged).
struct PointPair {
  Eigen::Vector3d merged, leaf, camera_centre;
};

std::unordered_map<std::uint32_t, std::size_t> ImageIndex(const std::vector<ColmapImage>& images) {
  std::unordered_map<std::uint32_t, std::size_t> index;
  for (std::size_t i = 0; i < images.size(); ++i) index.emplace(images[i].id, i);
  return index;
}

std::unordered_map<std::uint64_t, std::size_t> PointIndex(const std::vector<ColmapPoint>& points) {
  std::unordered_map<std::uint64_t, std::size_t> index;
  for (std::size_t i = 0; i < points.size(); ++i) index.emplace(points[i].id, i);
  return index;
}

// Every pair of 3D points the two models made of one 2D point of an image both registered (a pair
// of points once, however many shared images see it).
std::vector<PointPair> SharedPointPairs(const SparseModel& merged, const SparseModel& leaf, int* shared_images) {
  const auto merged_images = ImageIndex(merged.images);
  const auto merged_points = PointIndex(merged.points);
  const auto leaf_points = PointIndex(leaf.points);
  std::set<std::pair<std::uint64_t, std::uint64_t>> seen;
  std::vector<PointPair> pairs;
  *shared_images = 0;
  for (const ColmapImage& leaf_image : leaf.images) {
    const auto found = merged_images.find(leaf_image.id);
    if (found == merged_images.end()) continue;
    ++*shared_images;
    const ColmapImage& merged_image = merged.images[found->second];
    const std::size_t n = std::min(merged_image.point3d_ids.size(), leaf_image.point3d_ids.size());
    for (std::size_t k = 0; k < n; ++k) {
      const auto a = merged_points.find(merged_image.point3d_ids[k]);
      const auto b = leaf_points.find(leaf_image.point3d_ids[k]);
      // A 2D point without a 3D point in either model (or naming one the model lacks) pairs nothing.
      if (a == merged_points.end() || b == leaf_points.end() || !seen.emplace(a->first, b->first).second) continue;
      pairs.push_back({merged.points[a->second].point.xyz, leaf.points[b->second].point.xyz, merged_image.pose.Center()});
    }
  }
  return pairs;
}

bool Agrees(const PointPair& pair, const Sim3& transform, double max_angle) {
  const Eigen::Vector3d to_merged = pair.merged - pair.camera_centre;
  const Eigen::Vector3d to_moved = transform(pair.leaf) - pair.camera_centre;
  const double angle = std::atan2(to_merged.cross(to_moved).norm(), to_merged.dot(to_moved));
  return angle <= max_angle;
}

std::vector<int> InlierIndices(const std::vector<PointPair>& pairs, const Sim3& transform, double max_angle) {
  std::vector<int> inliers;
  for (std::size_t i = 0; i < pairs.size(); ++i)
    if (Agrees(pairs[i], transform, max_angle)) inliers.push_back(static_cast<int>(i));
  return inliers;
}

// The similarity through three pairs, or none when the leaf's three points are nearly on a line.
bool SimilarityOfThree(const std::vector<PointPair>& pairs, const int (&pick)[3], Sim3* transform) {
  Eigen::Matrix3d from, to;
  for (int c = 0; c < 3; ++c) {
    from.col(c) = pairs[static_cast<std::size_t>(pick[c])].leaf;
    to.col(c) = pairs[static_cast<std::size_t>(pick[c])].merged;
  }
  const Eigen::Vector3d u = from.col(1) - from.col(0), v = from.col(2) - from.col(0);
  if (u.cross(v).norm() < 0.05 * u.norm() * v.norm()) return false;  // under ~3 degrees: a line
  const Eigen::Matrix4d m = Eigen::umeyama(from, to, true);
  const double scale = m.block<3, 3>(0, 0).col(0).norm();
  if (!m.allFinite() || !(scale > 0)) return false;
  transform->scale = scale;
  transform->R = m.block<3, 3>(0, 0) / scale;
  transform->t = m.block<3, 1>(0, 3);
  return true;
}

// The similarity minimising the pairs' squared distances (Umeyama's closed form), `weighted`: each
// divided by its distance from the camera that sees it (weights 1/depth^2, depths under half the
// median's taken as half the median's), an angle, as the agreement is judged, so that the far
// points, whose positions the leaves know least, do not outweigh the near.
Sim3 FitToInliers(const std::vector<PointPair>& pairs, const std::vector<int>& inliers, bool weighted) {
  std::vector<double> depths;
  for (const int i : inliers)
    depths.push_back((pairs[static_cast<std::size_t>(i)].merged - pairs[static_cast<std::size_t>(i)].camera_centre).norm());
  std::vector<double> sorted = depths;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  // A point far nearer than the others (one of the leaf's at 0.1 of the median's depth) would
  // otherwise weigh hundreds of times as much as the rest and decide the rotation alone.
  const double nearest = std::max(0.5 * sorted[sorted.size() / 2], 1e-9);
  double total = 0;
  Eigen::Vector3d mean_leaf = Eigen::Vector3d::Zero(), mean_merged = Eigen::Vector3d::Zero();
  std::vector<double> weights;
  for (std::size_t k = 0; k < inliers.size(); ++k) {
    const PointPair& p = pairs[static_cast<std::size_t>(inliers[k])];
    const double depth = std::max(depths[k], nearest);
    weights.push_back(weighted ? 1 / (depth * depth) : 1.0);
    total += weights.back();
    mean_leaf += weights.back() * p.leaf;
    mean_merged += weights.back() * p.merged;
  }
  mean_leaf /= total;
  mean_merged /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double leaf_variance = 0;
  for (std::size_t k = 0; k < inliers.size(); ++k) {
    const PointPair& p = pairs[static_cast<std::size_t>(inliers[k])];
    const Eigen::Vector3d a = p.leaf - mean_leaf, b = p.merged - mean_merged;
    covariance += weights[k] * b * a.transpose();
    leaf_variance += weights[k] * a.squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d singular = svd.singularValues();
  if (!(singular(1) > 1e-12 * singular(0)) || !(leaf_variance > 0))
    throw Error("the leaf's agreeing points lie on one line: no rotation is determined by them");
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) sign(2, 2) = -1;
  Sim3 fit;
  fit.R = svd.matrixU() * sign * svd.matrixV().transpose();
  fit.scale = (singular.asDiagonal() * sign).trace() / leaf_variance;
  fit.t = mean_merged - fit.scale * fit.R * mean_leaf;
  return fit;
}

// COLMAP's convention for 2D points is OpenCV's pixel + 0.5.
double ObservationError(const calib::Camera& camera, const ColmapImage& image, std::uint32_t point2d_idx,
                        const Eigen::Vector3d& xyz) {
  const Eigen::Vector3d in_camera = image.pose.ToCamera(xyz);
  if (in_camera.z() <= 0) return std::numeric_limits<double>::infinity();
  return (camera.Project(in_camera) + Eigen::Vector2d(0.5, 0.5) - image.xy[point2d_idx]).norm();
}

// Observations that do not reproject within `max_error_px` are dropped, and points left with
// fewer than 2 (as model_merger filters after its merge).
void DropObservationsOverError(SparseModel* model, double max_error_px) {
  const auto image_of = ImageIndex(model->images);
  std::vector<ColmapPoint> kept;
  kept.reserve(model->points.size());
  for (ColmapPoint& point : model->points) {
    std::vector<TrackElement> track;
    for (const TrackElement& e : point.track) {
      ColmapImage& image = model->images[image_of.at(e.image_id)];
      if (ObservationError(model->camera, image, e.point2d_idx, point.point.xyz) <= max_error_px) {
        track.push_back(e);
      } else {
        image.point3d_ids[e.point2d_idx] = kInvalidPoint3D;
      }
    }
    if (track.size() < 2) {
      for (const TrackElement& e : track) model->images[image_of.at(e.image_id)].point3d_ids[e.point2d_idx] = kInvalidPoint3D;
      continue;
    }
    point.track = std::move(track);
    kept.push_back(std::move(point));
  }
  model->points = std::move(kept);
}

}  // namespace

std::string LeafMergeReport::Describe() const {
  return std::to_string(shared_images) + " shared frames, " + std::to_string(inliers) + " of " + std::to_string(pairs) +
         " point pairs agree; " + std::to_string(images_added) + " frames added, " + std::to_string(points_added) +
         " points added and " + std::to_string(points_joined) + " joined";
}

LeafAlignment AlignLeaf(const SparseModel& merged, const SparseModel& leaf, const LeafMergeOptions& options) {
  LeafAlignment result;
  LeafMergeReport& report = result.report;
  const std::vector<PointPair> pairs = SharedPointPairs(merged, leaf, &report.shared_images);
  report.pairs = static_cast<int>(pairs.size());
  if (report.shared_images < 3) {
    result.problem = "they share " + std::to_string(report.shared_images) + " registered frames, a merge needs 3";
    return result;
  }
  const int least = std::max(options.min_inliers, static_cast<int>(std::ceil(options.min_inlier_share * report.pairs)));
  if (report.pairs < least || report.pairs < 3) {
    result.problem = "their " + std::to_string(report.shared_images) + " shared frames hold " + std::to_string(report.pairs) +
                     " points triangulated in both, a merge needs " + std::to_string(std::max(least, 3));
    return result;
  }
  const double max_angle = options.max_error_px / merged.camera.fx;
  std::mt19937 rng(0);
  std::uniform_int_distribution<int> any(0, report.pairs - 1);
  std::vector<int> best;
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const int pick[3] = {any(rng), any(rng), any(rng)};
    Sim3 candidate;
    if (pick[0] == pick[1] || pick[0] == pick[2] || pick[1] == pick[2] || !SimilarityOfThree(pairs, pick, &candidate)) continue;
    std::vector<int> inliers = InlierIndices(pairs, candidate, max_angle);
    if (inliers.size() > best.size()) {
      best = std::move(inliers);
      report.leaf_to_merged = candidate;
    }
  }
  // Refitted to the agreeing pairs, in 3D and weighted by depth (FitToInliers), the fit that more
  // pairs agree with kept, while that number grows: neither fit wins on every leaf (the rendered
  // venue's leaves: one gained 356 agreeing pairs weighted, another lost 375).
  for (int round = 0; round < 5 && best.size() >= 3; ++round) {
    bool grew = false;
    for (const bool weighted : {false, true}) {
      Sim3 fit;
      try {
        fit = FitToInliers(pairs, best, weighted);
      } catch (const Error&) {
        continue;  // the agreeing points on one line: the fit before stays
      }
      std::vector<int> inliers = InlierIndices(pairs, fit, max_angle);
      if (inliers.size() > best.size()) {
        best = std::move(inliers);
        report.leaf_to_merged = fit;
        grew = true;
      }
    }
    if (!grew) break;
  }
  report.inliers = static_cast<int>(best.size());
  if (report.inliers < least) {
    result.problem = "of the " + std::to_string(report.pairs) + " points both triangulated in their " +
                     std::to_string(report.shared_images) + " shared frames, at most " + std::to_string(report.inliers) +
                     " agree under one similarity within " + std::to_string(static_cast<int>(options.max_error_px)) +
                     " px, a merge needs " + std::to_string(least);
  }
  return result;
}

void JoinLeaf(SparseModel* merged, const SparseModel& leaf, LeafAlignment* alignment, const LeafMergeOptions& options) {
  LeafMergeReport& report = alignment->report;
  const Sim3& transform = report.leaf_to_merged;
  auto image_of = ImageIndex(merged->images);
  const auto point_of = PointIndex(merged->points);
  std::unordered_set<std::uint32_t> added;
  for (const ColmapImage& image : leaf.images) {
    if (image_of.count(image.id)) continue;
    ColmapImage copy = image;
    const Rigid3 moved = transform.TransformPose(image.pose.ToRigid());
    copy.pose.q_cw = moved.rotation;
    copy.pose.t_cw = moved.translation;
    std::fill(copy.point3d_ids.begin(), copy.point3d_ids.end(), kInvalidPoint3D);
    image_of.emplace(copy.id, merged->images.size());
    merged->images.push_back(std::move(copy));
    added.insert(image.id);
  }
  report.images_added = static_cast<int>(added.size());
  std::uint64_t next_id = 1;
  for (const ColmapPoint& p : merged->points) next_id = std::max(next_id, p.id + 1);
  for (const ColmapPoint& point : leaf.points) {
    std::vector<TrackElement> fresh;  // observations the merged model does not triangulate yet
    std::set<std::uint64_t> existing;  // the merged model's points at the leaf point's shared observations
    for (const TrackElement& e : point.track) {
      const ColmapImage& image = merged->images[image_of.at(e.image_id)];
      const std::uint64_t there = added.count(e.image_id) ? kInvalidPoint3D : image.point3d_ids[e.point2d_idx];
      if (there == kInvalidPoint3D || !point_of.count(there)) {
        fresh.push_back(e);
      } else {
        existing.insert(there);
      }
    }
    std::uint64_t target = kInvalidPoint3D;
    ColmapPoint* into = nullptr;
    if (existing.size() == 1 && !fresh.empty()) {
      target = *existing.begin();  // one-to-one: the leaf's point is the merged model's
      into = &merged->points[point_of.at(target)];
      ++report.points_joined;
    } else if (fresh.size() >= 2) {
      target = next_id++;
      ColmapPoint moved = point;
      moved.id = target;
      moved.point.xyz = transform(point.point.xyz);
      moved.track.clear();
      merged->points.push_back(std::move(moved));
      into = &merged->points.back();
      ++report.points_added;
    } else {
      continue;
    }
    for (const TrackElement& e : fresh) {
      merged->images[image_of.at(e.image_id)].point3d_ids[e.point2d_idx] = target;
      into->track.push_back(e);
    }
  }
  DropObservationsOverError(merged, options.max_error_px);
}

}  // namespace arview::mapping
