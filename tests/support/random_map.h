#pragma once
// A map that matches nothing: random points in front of two keyframes, random descriptors. The
// tracker relocalizes (extracts, matches, fails) on every frame, so the per-frame loop of
// track/replay runs without COLMAP (cancellation and soak tests).

#include <filesystem>
#include <random>

#include "calib/camera.h"
#include "map/map_file.h"

namespace arview::testing {

inline void WriteRandomMap(const calib::Camera& camera, const std::filesystem::path& dir, int points = 400) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  map::Map map;
  map.camera = camera;
  for (int k = 0; k < 2; ++k) {
    map::Keyframe kf;
    kf.colmap_image_id = static_cast<std::uint32_t>(k + 1);
    kf.name = "frames/" + std::to_string(k) + ".png";
    kf.frame_index = k;
    kf.timestamp = k / 30.0;
    kf.pose.t_cw = Eigen::Vector3d(0.01 * k, 0, 0);
    map.keyframes.push_back(kf);
  }
  map.descriptors = cv::Mat(points, 128, CV_8U);
  cv::randu(map.descriptors, 0, 255);
  for (int i = 0; i < points; ++i) {
    map::MapPoint p;
    p.xyz = Eigen::Vector3d(coord(rng), coord(rng), 3.0 + coord(rng));
    p.first_descriptor = static_cast<std::uint32_t>(i);
    p.descriptor_count = 1;
    map.points.push_back(p);
    map.descriptor_point.push_back(static_cast<std::uint32_t>(i));
    const std::uint32_t k = static_cast<std::uint32_t>(i % 2);
    map.descriptor_keyframe.push_back(k);
    map::KeyframeObservation o;
    o.point = static_cast<std::uint32_t>(i);
    o.descriptor = static_cast<std::uint32_t>(i);
    o.pixel = Eigen::Vector2f(static_cast<float>(320 + 100 * p.xyz.x()), static_cast<float>(240 + 100 * p.xyz.y()));
    map.keyframes[k].observations.push_back(o);
  }
  std::filesystem::create_directories(dir);
  map::SaveMap(map, dir / map::kMapFileName);
}

}  // namespace arview::testing
