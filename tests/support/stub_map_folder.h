#pragma once
// Folders for the checks `arview map extend` and `arview map scale` make before they run COLMAP or
// write: a recording of one grey frame, and a map folder that holds what they look for
// (map.arvmap, database.db, a COLMAP model that is the map's own) without being one COLMAP could
// extend.

#include <cstdint>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
#include "fuzz/colmap_fixture.h"
#include "map/map_file.h"
#include "recordings/recording.h"
#include "tests/support/random_map.h"

namespace arview::testing {

inline calib::Camera CameraOfSize(int width, int height) {
  calib::Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 500;
  c.cx = width / 2.0 - 0.5;
  c.cy = height / 2.0 - 0.5;
  return c;
}

inline recordings::Recording OneFrameRecording(const std::filesystem::path& root, const calib::Camera& camera) {
  recordings::PrepareRecordingFolder(root, true);
  calib::SaveCamera(camera, root / "camera.yaml");
  cv::imwrite((root / "frames" / "000000.png").string(),
              cv::Mat(camera.height, camera.width, CV_8UC3, cv::Scalar(90, 90, 90)));
  recordings::WriteFramesTxt(root, {{0.0, "frames/000000.png"}});
  return recordings::LoadRecording(root);
}

// A map folder of a 640x480 camera (CameraOfSize): an empty database.db, sparse/0 holding the fuzz
// targets' small model (fuzz/colmap_fixture.h: two images, three points) and map.arvmap
// (WriteRandomMap) with that model's two keyframes, by id, name and pose: a folder whose model is
// its map's own, as the checks before COLMAP runs require.
inline void WriteStubMapFolder(const std::filesystem::path& dir) {
  WriteRandomMap(CameraOfSize(640, 480), dir);
  map::Map map = map::LoadMap(dir);
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const std::uint32_t id = static_cast<std::uint32_t>(k + 1);
    map.keyframes[k].colmap_image_id = id;
    map.keyframes[k].name = "frames/00000" + std::to_string(id) + ".png";
    map.keyframes[k].pose = calib::Pose{};
    map.keyframes[k].pose.t_cw = Eigen::Vector3d(0.1 * id, 0, 0);
  }
  map::SaveMap(map, dir / map::kMapFileName);
  std::ofstream(dir / "database.db") << "";
  const std::filesystem::path model = dir / "sparse" / "0";
  std::filesystem::create_directories(model);
  const fuzz::ColmapModelFiles files = fuzz::SmallColmapModel();
  std::ofstream(model / "cameras.bin", std::ios::binary) << files.cameras;
  std::ofstream(model / "images.bin", std::ios::binary) << files.images;
  std::ofstream(model / "points3D.bin", std::ios::binary) << files.points;
}

}  // namespace arview::testing
