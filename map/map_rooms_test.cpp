// A venue's map in parts (map/map_rooms.h) on a map made by the test: three rooms in a row, the
// first two sharing 20 points (a door both see through), the last two 10.

#include "map/map_rooms.h"

#include <gtest/gtest.h>

#include "map/map_file.h"

namespace arview::map {
namespace {

// Points 0-99; room 0's two keyframes see points 0-49, room 1's 30-79, room 2's 70-99.
Map ThreeRooms() {
  Map map;
  map.camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  map.rooms = {"hall", "office", "store"};
  const int first[3] = {0, 30, 70}, last[3] = {49, 79, 99};
  for (int room = 0; room < 3; ++room) {
    for (int copy = 0; copy < 2; ++copy) {
      Keyframe k;
      k.name = map.rooms[room] + "/" + std::to_string(copy) + ".png";
      k.room = room;
      k.colmap_image_id = static_cast<std::uint32_t>(map.keyframes.size() + 1);
      map.keyframes.push_back(k);
    }
  }
  std::vector<std::vector<std::pair<int, int>>> rows_of_point(100);  // (keyframe, copy)
  for (int p = 0; p < 100; ++p) {
    MapPoint point;
    point.xyz = Eigen::Vector3d(0.01 * p, 0, 2);
    point.first_descriptor = static_cast<std::uint32_t>(map.descriptor_point.size());
    for (int k = 0; k < 6; ++k) {
      const int room = k / 2;
      if (p < first[room] || p > last[room]) continue;
      KeyframeObservation o;
      o.point = static_cast<std::uint32_t>(p);
      o.pixel = Eigen::Vector2f(static_cast<float>(p), static_cast<float>(k));
      o.descriptor = static_cast<std::uint32_t>(map.descriptor_point.size());
      map.keyframes[k].observations.push_back(o);
      map.descriptor_point.push_back(static_cast<std::uint32_t>(p));
      map.descriptor_keyframe.push_back(static_cast<std::uint32_t>(k));
    }
    point.descriptor_count = static_cast<std::uint32_t>(map.descriptor_point.size()) - point.first_descriptor;
    map.points.push_back(point);
  }
  map.descriptors = cv::Mat(static_cast<int>(map.descriptor_point.size()), 128, CV_8UC1);
  for (int r = 0; r < map.descriptors.rows; ++r) map.descriptors.row(r).setTo(r % 256);
  ValidateMap(map, "the test's map");
  return map;
}

TEST(MapRooms, RoomsSharingEnoughPointsAreNeighbours) {
  const Map map = ThreeRooms();
  const auto neighbours = RoomNeighbours(map);
  EXPECT_EQ(neighbours[0], std::vector<int>{1});
  EXPECT_EQ(neighbours[1], std::vector<int>{0});
  EXPECT_TRUE(neighbours[2].empty()) << "10 shared points are under the default 20";
  EXPECT_EQ(RoomNeighbours(map, {10, 0.02})[1], (std::vector<int>{0, 2}));
  EXPECT_TRUE(RoomNeighbours(map, {10, 0.5})[1].empty()) << "20 of 50 points are under half of them";
  EXPECT_EQ(RoomWithNeighbours(map, 0), (std::vector<int>{0, 1}));
  EXPECT_TRUE(RoomNeighbours(Map{}).empty());
}

TEST(MapRooms, APartHoldsItsRoomsKeyframesAndTheirPointsAndIsAValidMap) {
  const Map map = ThreeRooms();
  const Map part = RoomsPart(map, {0, 1});
  ValidateMap(part, "the part");
  ASSERT_EQ(part.keyframes.size(), 4u);
  EXPECT_EQ(part.keyframes[3].name, "office/1.png");
  ASSERT_EQ(part.points.size(), 80u);  // points 0-79
  EXPECT_EQ(part.points[79].xyz, map.points[79].xyz);
  EXPECT_EQ(part.points[75].descriptor_count, 2u) << "point 75 kept the office's two rows, not the store's";
  EXPECT_EQ(part.descriptors.rows, 2 * 50 + 2 * 50);
  // Each observation still names its own point and its own descriptor bytes.
  for (const Keyframe& k : part.keyframes) {
    for (const KeyframeObservation& o : k.observations) {
      EXPECT_EQ(o.pixel.x(), static_cast<float>(&part.points[o.point] - &part.points[0]));
    }
  }
  const KeyframeObservation& first = part.keyframes[2].observations.front();  // office's first keyframe, point 30
  EXPECT_EQ(first.point, 30u);
  const int old_row = static_cast<int>(map.keyframes[2].observations.front().descriptor);
  EXPECT_EQ(cv::norm(part.descriptors.row(static_cast<int>(first.descriptor)), map.descriptors.row(old_row), cv::NORM_L1), 0);
  EXPECT_EQ(part.rooms, map.rooms);
}

TEST(MapRooms, AnUnknownRoomNamesTheRoomsThereAre) {
  const Map map = ThreeRooms();
  EXPECT_EQ(RoomIndex(map, "office"), 1);
  try {
    RoomIndex(map, "attic");
    FAIL() << "an unknown room went through";
  } catch (const MapError& e) {
    EXPECT_STREQ(e.what(), "the map has no room 'attic'; its rooms are hall, office, store");
  }
  EXPECT_THROW(RoomIndex(Map{}, "hall"), MapError);
}

}  // namespace
}  // namespace arview::map
