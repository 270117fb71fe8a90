#include "synth/venue_layout.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "recordings/recording.h"
#include "render/test_scene.h"
#include "synth/synth_venue.h"

namespace arview::synth {
namespace {

namespace fs = std::filesystem;

double AngleDeg(const calib::Pose& a, const calib::Pose& b) { return a.q_cw.angularDistance(b.q_cw) * 180 / M_PI; }

TEST(VenueWalk, GoesThroughEveryRoomInOrderCrossingAtTheDoorsOnly) {
  const VenueLayout venue;  // 3 rooms
  const double fps = 30, duration = 720 / fps;
  const VenueWalk walk(venue, duration);
  std::vector<int> rooms_in_order;
  double widest_step = 0, widest_turn = 0, turned_in_room[3] = {0, 0, 0};
  calib::Pose previous = walk.At(0);
  for (int i = 0; i <= 720; ++i) {
    const calib::Pose pose = walk.At(i / fps);
    const Eigen::Vector3d c = pose.Center();
    const int room = venue.RoomAt(c);
    ASSERT_GE(room, 0) << "frame " << i << " outside the venue at " << c.transpose();
    if (rooms_in_order.empty() || rooms_in_order.back() != room) rooms_in_order.push_back(room);
    widest_step = std::max(widest_step, (c - previous.Center()).norm());
    widest_turn = std::max(widest_turn, AngleDeg(pose, previous));
    turned_in_room[room] += AngleDeg(pose, previous);
    // Away from the walls, except in a doorway: a camera never films a wall from closer than 0.5 m.
    const double to_side_wall = venue.room_width / 2 - std::abs(c.y());
    const double x_in_room = c.x() - (venue.RoomCentreX(room) - venue.room_length / 2);
    const double to_end_wall = std::min(x_in_room, venue.room_length - x_in_room);
    EXPECT_GT(to_side_wall, 0.5) << "frame " << i;
    if (to_end_wall < 0.5) {
      EXPECT_LT(std::abs(c.y()), venue.door_width / 2 - 0.3) << "frame " << i << ": not in the doorway";
    }
    EXPECT_NEAR(c.z(), VenueWalk::kCameraHeight, 1e-9);
    previous = pose;
  }
  EXPECT_EQ(rooms_in_order, (std::vector<int>{0, 1, 2}));
  for (int room = 0; room < 3; ++room) EXPECT_GT(turned_in_room[room], 350) << "room " << room << ": a full turn";
  // Smooth at 30 fps: a walking pace and a turn a tracker follows.
  EXPECT_LT(widest_step, 0.1);
  EXPECT_LT(widest_turn, 4.5);
  // The room changes where the walk goes through a door.
  for (int door = 0; door < 2; ++door) {
    EXPECT_EQ(venue.RoomAt(walk.At(walk.DoorTime(door) - 0.1).Center()), door);
    EXPECT_EQ(venue.RoomAt(walk.At(walk.DoorTime(door) + 0.1).Center()), door + 1);
  }
}

TEST(VenueScene, EveryPanelHasATextureOfItsOwnAndTheSceneIsTheSameForASeed) {
  const VenueLayout venue;
  const RoomScene a = MakeVenueScene(venue, 1), b = MakeVenueScene(venue, 1), c = MakeVenueScene(venue, 2);
  // Per room: 2 + 2 on the side walls, 4 floor quarters, 1 on the ceiling; on the end walls 2
  // beside each door on each side of it (2 doors), 1 on each far end.
  EXPECT_EQ(a.panels.size(), 3u * (4 + 4 + 1) + 2 * 2 * 2 + 2);
  std::set<std::string> names;
  for (const RoomPanel& p : a.panels) names.insert(p.image_name);
  EXPECT_EQ(names.size(), a.panels.size()) << "a texture seen in two places would be matched across them";
  auto same = [](const cv::Mat& x, const cv::Mat& y) { return cv::norm(x, y, cv::NORM_L1) == 0; };
  EXPECT_TRUE(same(a.textures[5], b.textures[5]));
  EXPECT_FALSE(same(a.textures[5], c.textures[5]));
  EXPECT_FALSE(same(a.textures[5], a.textures[6]));
}

TEST(SynthVenue, WritesARecordingWithItsGroundTruthAndEachFramesRoom) {
  const fs::path out = fs::temp_directory_path() / ("arview_synth_venue_" + std::to_string(::getpid()));
  fs::remove_all(out);
  SynthVenueOptions o;
  o.out = out;
  o.frames = 240;
  o.width = 160;
  o.height = 120;
  o.samples = 1;
  const VenueWalk walk(o.layout, o.frames / o.fps);
  const int before_door = static_cast<int>(walk.DoorTime(0) * o.fps);
  o.frames_subset = "0," + std::to_string(before_door) + "," + std::to_string(before_door + 2);
  ASSERT_EQ(SynthesizeVenue(o), 3);

  const recordings::Recording recording = recordings::LoadRecording(out);
  ASSERT_EQ(recording.frames.size(), 3u);
  ASSERT_TRUE(recording.groundtruth.has_value());
  EXPECT_LT(((*recording.groundtruth)[1].pose.Center() - walk.At(before_door / o.fps).Center()).norm(), 1e-6);
  std::ifstream rooms(out / "rooms.txt");
  std::string line, names;
  while (std::getline(rooms, line)) {
    if (!line.empty() && line[0] != '#') names += line.substr(line.find(' ') + 1) + " ";
  }
  EXPECT_EQ(names, "room-1 room-1 room-2 ");
  // Every frame sees textured walls, not the void beyond them (the far plane, a gap).
  for (int i = 0; i < 3; ++i) {
    cv::Scalar mean, deviation;
    cv::meanStdDev(recording.ReadImage(i), mean, deviation);
    EXPECT_GT(deviation[1], 20) << "frame " << i;
  }
  // A second run into the same folder is refused; --force replaces it.
  EXPECT_THROW(SynthesizeVenue(o), render::RenderError);
  o.overwrite = true;
  EXPECT_EQ(SynthesizeVenue(o), 3);
  o.layout.rooms = 5;
  EXPECT_THROW(SynthesizeVenue(o), render::RenderError);
  fs::remove_all(out);
}

}  // namespace
}  // namespace arview::synth
