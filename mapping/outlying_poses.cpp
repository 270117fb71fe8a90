#include "mapping/outlying_poses.h"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <unordered_map>

#include "base/stats.h"

namespace arview::mapping {

void OutlyingPoseOptions::Check(const OptionNames& names) const {
  RequireOption(min_median_px > 0, names("min_median_px"), "above 0 (pixels)", min_median_px);
  RequireOption(over_model_median >= 1, names("over_model_median"), "at least 1", over_model_median);
  RequireOption(min_observations >= 6, names("min_observations"), "at least 6", min_observations);
  RequireOption(ransac_px > 0, names("ransac_px"), "above 0 (pixels)", ransac_px);
  RequireOption(keep_below_share > 0 && keep_below_share <= 1, names("keep_below_share"), "in (0, 1]", keep_below_share);
}

namespace {

// An image's observations: its 2D points in OpenCV's pixel convention and their 3D points.
struct Observations {
  std::vector<cv::Point2d> pixels;
  std::vector<cv::Point3d> points;
};

Observations ObservationsOf(const ColmapImage& image, const std::unordered_map<std::uint64_t, const ColmapPoint*>& points) {
  Observations o;
  for (std::size_t k = 0; k < image.point3d_ids.size(); ++k) {
    const auto p = points.find(image.point3d_ids[k]);
    if (image.point3d_ids[k] == kInvalidPoint3D || p == points.end()) continue;
    o.pixels.emplace_back(image.xy[k].x() - 0.5, image.xy[k].y() - 0.5);  // COLMAP's pixel centre at 0.5
    o.points.emplace_back(p->second->point.xyz.x(), p->second->point.xyz.y(), p->second->point.xyz.z());
  }
  return o;
}

std::vector<double> Residuals(const calib::Camera& camera, const calib::Pose& pose, const Observations& o) {
  std::vector<double> residuals;
  for (std::size_t k = 0; k < o.points.size(); ++k) {
    const Eigen::Vector3d c = pose.ToCamera({o.points[k].x, o.points[k].y, o.points[k].z});
    if (c.z() <= 0) {
      residuals.push_back(1e6);
      continue;
    }
    const Eigen::Vector2d px = camera.Project(c);
    residuals.push_back(std::hypot(px.x() - o.pixels[k].x, px.y() - o.pixels[k].y));
  }
  return residuals;
}

// The pose RANSAC and LM give for `o`, or none.
std::optional<calib::Pose> PoseAgain(const calib::Camera& camera, const Observations& o, double ransac_px) {
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const cv::Mat K(camera.K());
  if (!cv::solvePnPRansac(o.points, o.pixels, K, camera.DistCoeffs(), rvec, tvec, false, 1000,
                          static_cast<float>(ransac_px), 0.999, inliers, cv::SOLVEPNP_AP3P) ||
      inliers.size() < 6)
    return std::nullopt;
  std::vector<cv::Point3d> in_points;
  std::vector<cv::Point2d> in_pixels;
  for (const int i : inliers) {
    in_points.push_back(o.points[static_cast<std::size_t>(i)]);
    in_pixels.push_back(o.pixels[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(in_points, in_pixels, K, camera.DistCoeffs(), rvec, tvec);
  return calib::PoseFromOpenCv(rvec, tvec);
}

}  // namespace

std::vector<RePosedImage> RePoseOutlyingImages(SparseModel* model, const OutlyingPoseOptions& options) {
  options.Check();
  std::unordered_map<std::uint64_t, const ColmapPoint*> points;
  for (const ColmapPoint& p : model->points) points[p.id] = &p;
  std::vector<Observations> observations;
  std::vector<double> medians;
  for (const ColmapImage& image : model->images) {
    observations.push_back(ObservationsOf(image, points));
    medians.push_back(Median(Residuals(model->camera, image.pose, observations.back())));
  }
  const double model_median = Median(medians);
  std::vector<RePosedImage> out;
  for (std::size_t i = 0; i < model->images.size(); ++i) {
    const Observations& o = observations[i];
    if (static_cast<int>(o.points.size()) < options.min_observations || medians[i] <= options.min_median_px ||
        medians[i] <= options.over_model_median * model_median)
      continue;
    RePosedImage r{model->images[i].name, static_cast<int>(o.points.size()), medians[i], medians[i], false};
    if (const auto pose = PoseAgain(model->camera, o, options.ransac_px)) {
      r.median_after_px = Median(Residuals(model->camera, *pose, o));
      if (r.median_after_px <= options.keep_below_share * r.median_before_px) {
        model->images[i].pose = *pose;
        r.kept = true;
      }
    }
    out.push_back(r);
  }
  return out;
}

std::vector<RePosedImage> RePoseOutlyingImagesIn(const std::filesystem::path& sparse_dir, const OutlyingPoseOptions& options) {
  SparseModel model = ReadSparseModel(sparse_dir);
  const std::vector<RePosedImage> re_posed = RePoseOutlyingImages(&model, options);
  if (std::any_of(re_posed.begin(), re_posed.end(), [](const RePosedImage& r) { return r.kept; }))
    WriteSparseModel(model, sparse_dir);
  return re_posed;
}

std::string Describe(const RePosedImage& image) {
  char text[160];
  std::snprintf(text, sizeof text, ": its %d observations at a median of %.2f px, posed again: %.2f px%s", image.observations,
                image.median_before_px, image.median_after_px, image.kept ? "" : " (not better: kept as it was)");
  return image.name + text;
}

}  // namespace arview::mapping
