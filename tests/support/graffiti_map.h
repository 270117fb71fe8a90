#pragma once
// The graffiti plane the tracker's tests map (tracker/test_planar_scene.h) as the commands meet
// it: a map folder as `arview map` leaves one, and a recording of views of the plane. The
// cameras look down on it from one side, so that `arview place` takes the plane for the floor.
// Needs the graffiti texture (Debian package opencv-doc): callers check
// tracker::testing::kGraffitiTexture first.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
#include "map/map_file.h"
#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "tracker/test_planar_scene.h"

namespace arview::testing {

// The plane's map as `arview map` leaves a folder, less COLMAP's own files: map.arvmap, the
// keyframes' poses, a picture, and the keyframes' images where a video map keeps them.
inline void WriteGraffitiMapFolder(const std::filesystem::path& folder) {
  const tracker::testing::GraffitiPlane& plane = *tracker::testing::SharedGraffitiPlane();
  map::Map map = plane.map;
  std::filesystem::create_directories(folder / "images");
  recordings::Trajectory keyframes;
  for (map::Keyframe& keyframe : map.keyframes) {
    keyframe.name += ".png";
    ASSERT_TRUE(cv::imwrite((folder / "images" / keyframe.name).string(), plane.world.Render(keyframe.pose)));
    keyframes.push_back({keyframe.timestamp, keyframe.pose});
  }
  map::SaveMap(map, folder / map::kMapFileName);
  recordings::WriteTum(keyframes, folder / "keyframes.txt", "keyframes");
  ASSERT_TRUE(cv::imwrite((folder / "map.png").string(), plane.texture));
}

// 24 views along a slow arc over the plane at 10 frames a second, the first `dark` of them at a
// twentieth of the light (first: no motion prior carries the tracker over them).
inline void WriteGraffitiViews(const std::filesystem::path& folder, int dark = 6) {
  const tracker::testing::GraffitiPlane& plane = *tracker::testing::SharedGraffitiPlane();
  recordings::PrepareRecordingFolder(folder, false);
  calib::SaveCamera(plane.world.camera(), folder / "camera.yaml");
  std::vector<recordings::FrameEntry> frames;
  for (int i = 0; i < 24; ++i) {
    const double a = 0.004 * i;
    cv::Mat view = plane.world.Render(tracker::testing::LookAt({-0.15 + a, 0.05 * std::sin(3 * a), -0.8 - 0.1 * a}, {0.02, 0, 0}));
    if (i < dark) view.convertTo(view, -1, 0.05);
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", i);
    ASSERT_TRUE(cv::imwrite((folder / name).string(), view));
    frames.push_back({0.1 * i, name});
  }
  recordings::WriteFramesTxt(folder, frames);
}

}  // namespace arview::testing
