// map.arvmap through map::LoadMap (header, counts, checksum, then ValidateMap).
#include <exception>
#include <random>

#include "fuzz/fuzz_support.h"
#include "map/map_file.h"

namespace {

using namespace arview::map;

// Three keyframes seeing ten points (as map/map_file_test.cpp's SmallMap): a valid file that
// exercises every section of the format.
Map SmallMap() {
  Map map;
  map.camera = arview::calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 3; ++k) {
    Keyframe kf;
    kf.colmap_image_id = static_cast<std::uint32_t>(k + 1);
    kf.name = "frames/" + std::to_string(k) + ".png";
    kf.frame_index = 2 * k;
    kf.timestamp = 0.5 * k;
    kf.pose = arview::calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.3 * k, 0, 0));
    map.keyframes.push_back(kf);
  }
  const int points = 10;
  map.descriptors.create(points * 3, 128, CV_8UC1);
  for (int i = 0; i < points; ++i) {
    MapPoint p;
    p.xyz = Eigen::Vector3d(u(rng), u(rng), 4 + u(rng));
    p.rgb = {static_cast<std::uint8_t>(i), 20, 30};
    p.reprojection_error = 0.1 * i;
    p.first_descriptor = static_cast<std::uint32_t>(3 * i);
    p.descriptor_count = 3;
    map.points.push_back(p);
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t row = static_cast<std::uint32_t>(3 * i) + k;
      map.descriptors.row(static_cast<int>(row)).setTo(cv::Scalar((row * 7) % 256));
      map.descriptor_point.push_back(static_cast<std::uint32_t>(i));
      map.descriptor_keyframe.push_back(k);
      const Eigen::Vector2d px = map.camera.Project(map.keyframes[k].pose.ToCamera(p.xyz));
      map.keyframes[k].observations.push_back({static_cast<std::uint32_t>(i), px.cast<float>(), row});
    }
  }
  return map;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (!seeds.empty()) SaveMap(SmallMap(), seeds / "small.arvmap");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("map.arvmap", data, size);
  try {
    (void)arview::map::LoadMap(file);
  } catch (const std::exception&) {
  }
  return 0;
}
