// A room light file (<scene>.light.yml) through room::LoadRoomLight (the size and shape
// checks, then OpenCV's FileStorage).
#include <exception>

#include "fuzz/fuzz_support.h"
#include "room/room_light.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  arview::room::RoomLight light;
  light.sh[0] = {1.6, 1.7, 1.5};
  light.sh[2] = {0.2, 0.2, 0.1};
  light.dominant.direction = {0, 0, 1};
  light.dominant.color = {1, 1, 1};
  light.keyframes = 1;
  arview::room::KeyframeThumbnail thumbnail;
  thumbnail.intrinsics = {50, 50, 2, 1.5};
  thumbnail.image_size = {4, 3};
  thumbnail.linear_bgr = cv::Mat(3, 4, CV_32FC3, cv::Scalar(0.5f, 0.4f, 0.3f));
  light.thumbnails.push_back(thumbnail);
  light.scene_triangles = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  light.occluder_triangles = light.scene_triangles;
  arview::room::SaveRoomLight(light, seeds / "small.light.yml");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("room.light.yml", data, size);
  try {
    (void)arview::room::LoadRoomLight(file);
  } catch (const std::exception&) {
    // A refused file is the expected outcome; only crashes, hangs and sanitizer reports count.
  }
  return 0;
}
