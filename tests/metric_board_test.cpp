// A board lying on the rendered room's floor, found in rendered frames by the same detector
// `arview map --board` uses, triangulated with exact poses put in an arbitrary frame (as COLMAP's
// is) and fitted: the map's metres and up against the room's exact ones (docs/mapping.md,
// "Metric scale and up"). The COLMAP part of the chain is measured on whole maps in the docs.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "mapping/metric_frame.h"
#include "render/test_scene.h"
#include "synth/orbit_walk.h"
#include "synth/synth_room.h"

namespace arview {
namespace {

constexpr double kDeg = M_PI / 180;

struct RenderedBoardMap {
  map::Map map;
  std::vector<cv::Mat> images;  // grey, by keyframe
  Sim3 room_to_map;
};

// The demo's first lap every 14th frame with its board, the poses moved into a frame of
// scale 0.31, turned and shifted.
RenderedBoardMap RenderFirstLap(const synth::FloorBoard& board) {
  RenderedBoardMap out;
  out.room_to_map.scale = 0.31;
  out.room_to_map.R = Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 0.5, -0.2).normalized()).toRotationMatrix();
  out.room_to_map.t = {0.4, 3, -1};
  const synth::RoomScene scene = synth::MakeRoomScene(synth::kOpenCvDocData, synth::SynthLighting::kWindow, board);
  const calib::Camera camera = synth::RoomCamera();
  synth::RoomRenderer renderer(render::testing::SharedContext(), scene, camera, 4);
  const synth::OrbitWalk walk(1340 / 30.0, 1);
  out.map.camera = camera;
  for (int i = 0; i < 670; i += 14) {
    const calib::Pose pose = walk.At(i / 30.0);
    cv::Mat grey;
    cv::cvtColor(renderer.Render(pose), grey, cv::COLOR_BGR2GRAY);
    map::Keyframe k;
    k.name = "frames/" + std::to_string(i) + ".png";
    k.frame_index = i;
    k.pose = calib::Pose::FromRigid(out.room_to_map.TransformPose(pose.ToRigid()));
    out.map.keyframes.push_back(k);
    out.images.push_back(grey);
  }
  return out;
}

TEST(MetricBoard, ABoardOnTheRenderedFloorGivesTheRoomsMetresAndUp) {
  synth::FloorBoard board;
  board.inner_corners = {9, 6};
  board.square = 0.08;
  board.centre = synth::OrbitWalkOptions{}.subject + Eigen::Vector2d(1.1, 0);
  const RenderedBoardMap rendered = RenderFirstLap(board);
  const std::vector<mapping::BoardSighting> seen =
      mapping::FindBoard(rendered.map, [&](std::size_t k) { return rendered.images[k]; }, board.inner_corners);
  ASSERT_GE(seen.size(), 3u) << "the first lap should see the whole board in several frames";
  const mapping::TriangulatedBoard triangulated = mapping::TriangulateBoard(rendered.map, seen, board.inner_corners);
  EXPECT_LT(triangulated.rms_reprojection_px, 0.5);
  const mapping::MetricFit fit = mapping::FitFromBoard(rendered.map, triangulated, {board.inner_corners, board.square, true});

  // map → metric after room → map: the identity up to a turn about z and a shift on the floor.
  const Sim3 room_to_metric = mapping::Compose(fit.to_metric, rendered.room_to_map);
  const double up_error = std::acos(std::clamp((room_to_metric.R * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0)) / kDeg;
  std::printf("board seen in %zu of %zu frames, corners %.3f px; scale %.5f, up %.3f deg off, fit %.2f mm\n",
              triangulated.keyframes.size(), rendered.map.keyframes.size(), triangulated.rms_reprojection_px,
              room_to_metric.scale, up_error, 1000 * fit.fit_rms_m);
  EXPECT_NEAR(room_to_metric.scale, 1.0, 0.01);  // the bound: 1%
  EXPECT_LT(up_error, 1.0);                      // and 1 degree
  // The origin is the board's centre (on its printed face, 8 mm above the floor).
  const Eigen::Vector3d centre = room_to_metric(Eigen::Vector3d(board.centre.x(), board.centre.y(), 0.008));
  EXPECT_LT(centre.norm(), 0.01) << centre.transpose();
  // Every triangulated corner lies on a true one.
  for (const Eigen::Vector3d& corner : triangulated.corners) {
    const Eigen::Vector3d in_room = rendered.room_to_map.Inverse()(corner);
    double nearest = 1e9;
    for (const Eigen::Vector3d& truth : board.Corners()) nearest = std::min(nearest, (truth - in_room).norm());
    EXPECT_LT(nearest, 0.005);
  }
  EXPECT_LT(fit.frame.scale_error, 0.01);
}

}  // namespace
}  // namespace arview
