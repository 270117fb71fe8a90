#pragma once
// Folders for the checks `arview map extend` makes before it runs COLMAP: a recording of one grey
// frame, and a map folder that holds what an extension looks for (map.arvmap, database.db, a
// COLMAP model) without being one COLMAP could extend.

#include <cstdint>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
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

// map.arvmap (WriteRandomMap), an empty database.db and sparse/0/images.bin counting two images.
inline void WriteStubMapFolder(const calib::Camera& camera, const std::filesystem::path& dir) {
  WriteRandomMap(camera, dir);
  std::ofstream(dir / "database.db") << "";
  std::filesystem::create_directories(dir / "sparse" / "0");
  const std::uint64_t two_images = 2;
  std::ofstream(dir / "sparse" / "0" / "images.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(&two_images), sizeof two_images);
}

}  // namespace arview::testing
