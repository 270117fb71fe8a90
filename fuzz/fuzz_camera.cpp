// camera.yaml through calib::LoadCamera (the pre-checks, then OpenCV's FileStorage).
#include <exception>

#include "calib/camera.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  arview::calib::Camera camera = arview::calib::Camera::Pinhole(640, 480, 500, 502, 319.5, 239.5);
  arview::calib::SaveCamera(camera, seeds / "pinhole.yaml");
  camera.dist = {-0.1, 0.01, 0.001, -0.002, 0.0005};
  arview::calib::SaveCamera(camera, seeds / "distorted.yaml");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("camera.yaml", data, size);
  try {
    (void)arview::calib::LoadCamera(file);
  } catch (const std::exception&) {
    // A refused file is the expected outcome; only crashes, hangs and sanitizer reports count.
  }
  return 0;
}
