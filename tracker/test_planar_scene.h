#pragma once
// A textured plane (world z = 0) seen by a distorted camera: exact renderings from any pose and
// a Map built from SIFT on rendered keyframes, for tests and benchmarks that need real image
// features with exact ground truth before a COLMAP map is at hand.

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <memory>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"
#include "map/map.h"
#include "tracker/features.h"
#include "tracker/test_scene.h"

namespace arview::tracker::testing {

// World pose of a camera at `centre` looking at `target`, image-up along `up`.
inline calib::Pose LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& up = -Eigen::Vector3d::UnitY()) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d y = -(up - up.dot(z) * z).normalized();
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d R_wc;
  R_wc << x, y, z;
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(R_wc), centre);
}

class PlanarWorld {
 public:
  // texture: any image; texel (u, v) sits at world (u − W/2, v − H/2, 0) · metres_per_texel.
  PlanarWorld(const cv::Mat& texture, const calib::Camera& camera, double metres_per_texel)
      : texture_(ToGray8(texture)), camera_(camera), scale_(metres_per_texel),
        bearings_(camera.height, camera.width, CV_64FC3) {
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        const Eigen::Vector3d b = camera.Unproject({double(x), double(y)});
        bearings_.at<cv::Vec3d>(y, x) = {b.x(), b.y(), b.z()};
      }
  }

  const calib::Camera& camera() const { return camera_; }

  // Where the ray of pixel (x, y) meets the plane; false when it does not (in front).
  bool Intersect(const calib::Pose& pose, const Eigen::Vector3d& bearing, Eigen::Vector3d* X) const {
    const Eigen::Vector3d d = pose.q_cw.conjugate() * bearing;
    const Eigen::Vector3d C = pose.Center();
    if (std::abs(d.z()) < 1e-9) return false;
    const double s = -C.z() / d.z();
    if (s <= 0) return false;
    *X = C + s * d;
    return true;
  }

  cv::Mat Render(const calib::Pose& pose) const {
    cv::Mat map_x(camera_.height, camera_.width, CV_32F), map_y(camera_.height, camera_.width, CV_32F);
    for (int y = 0; y < camera_.height; ++y)
      for (int x = 0; x < camera_.width; ++x) {
        const cv::Vec3d& b = bearings_.at<cv::Vec3d>(y, x);
        Eigen::Vector3d X;
        float u = -1e4f, v = -1e4f;
        if (Intersect(pose, {b[0], b[1], b[2]}, &X)) {
          u = static_cast<float>(X.x() / scale_ + texture_.cols / 2.0);
          v = static_cast<float>(X.y() / scale_ + texture_.rows / 2.0);
        }
        map_x.at<float>(y, x) = u;
        map_y.at<float>(y, x) = v;
      }
    cv::Mat out;
    cv::remap(texture_, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    return out;
  }

  // A map whose points are the SIFT keypoints of renderings from `keyframes`, each keypoint its
  // own point with one descriptor, placed exactly on the plane.
  map::Map MakeMap(const std::vector<calib::Pose>& keyframes, const SiftExtractor& sift) const {
    map::Map map;
    map.camera = camera_;
    std::vector<cv::Mat> rows;
    for (size_t k = 0; k < keyframes.size(); ++k) {
      map::Keyframe kf;
      kf.colmap_image_id = static_cast<std::uint32_t>(k + 1);
      kf.name = "kf" + std::to_string(k);
      kf.frame_index = static_cast<int>(k);
      kf.timestamp = static_cast<double>(k);
      kf.pose = keyframes[k];
      const Features f = sift.Extract(Render(keyframes[k]));
      for (size_t i = 0; i < f.keypoints.size(); ++i) {
        const cv::Point2f& p = f.keypoints[i].pt;
        Eigen::Vector3d X;
        if (!Intersect(keyframes[k], camera_.Unproject({p.x, p.y}), &X)) continue;
        const auto id = static_cast<std::uint32_t>(map.points.size());
        const auto row = static_cast<std::uint32_t>(map.descriptor_point.size());
        map::MapPoint mp;
        mp.xyz = X;
        mp.first_descriptor = row;
        mp.descriptor_count = 1;
        map.points.push_back(mp);
        map.descriptor_point.push_back(id);
        map.descriptor_keyframe.push_back(static_cast<std::uint32_t>(k));
        rows.push_back(f.descriptors.row(static_cast<int>(i)));
        kf.observations.push_back({id, Eigen::Vector2f(p.x, p.y), row});
      }
      map.keyframes.push_back(std::move(kf));
    }
    cv::vconcat(rows, map.descriptors);
    return map;
  }

 private:
  cv::Mat texture_;
  calib::Camera camera_;
  double scale_;
  cv::Mat bearings_;
};

inline constexpr const char* kGraffitiTexture = "/usr/share/doc/opencv-doc/examples/data/graf1.png";

// The four keyframes ~0.9 m from the plane that the tracker's tests map the graffiti from.
inline std::vector<calib::Pose> GraffitiKeyframes() {
  return {LookAt({0, 0, -0.9}, {0, 0, 0}), LookAt({0.3, 0, -0.85}, {0.05, 0, 0}),
          LookAt({-0.3, 0.1, -0.85}, {-0.05, 0, 0}), LookAt({0, -0.25, -0.85}, {0, -0.05, 0})};
}

// The graffiti texture on a 1.2 m x 0.96 m plane seen by TestCamera(), mapped from
// GraffitiKeyframes(): built once per test binary; null without the texture (opencv-doc).
struct GraffitiPlane {
  cv::Mat texture;
  PlanarWorld world;
  map::Map map;
};
inline const GraffitiPlane* SharedGraffitiPlane() {
  static const std::unique_ptr<GraffitiPlane> plane = []() -> std::unique_ptr<GraffitiPlane> {
    const cv::Mat texture = cv::imread(kGraffitiTexture);
    if (texture.empty()) return nullptr;
    PlanarWorld world(texture, TestCamera(), 0.0015);
    map::Map map = world.MakeMap(GraffitiKeyframes(), SiftExtractor());
    return std::make_unique<GraffitiPlane>(GraffitiPlane{texture, std::move(world), std::move(map)});
  }();
  return plane.get();
}

}  // namespace arview::tracker::testing
