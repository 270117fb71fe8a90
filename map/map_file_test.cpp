#include "map/map_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <random>

namespace arview::map {
namespace {

namespace fs = std::filesystem;

// A small consistent map: 3 keyframes on a line looking down +z, points in front of them,
// each point seen by every keyframe, observations exactly at the projections.
Map SmallMap() {
  Map map;
  map.camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 3; ++k) {
    Keyframe kf;
    kf.colmap_image_id = static_cast<std::uint32_t>(k + 1);
    kf.name = "frames/" + std::to_string(k) + ".png";
    kf.frame_index = 2 * k;
    kf.timestamp = 0.5 * k;
    kf.pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.3 * k, 0, 0));
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

class MapFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_map_file_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<char> Bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void Write(const fs::path& p, const std::vector<char>& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  fs::path dir_;
};

TEST_F(MapFileTest, RoundTripKeepsEverything) {
  const Map map = SmallMap();
  SaveMap(map, dir_ / kMapFileName);
  const Map back = LoadMap(dir_);  // a directory finds map.arvmap
  EXPECT_EQ(back.camera.fx, map.camera.fx);
  EXPECT_EQ(back.camera.cx, map.camera.cx);
  ASSERT_EQ(back.keyframes.size(), map.keyframes.size());
  for (size_t k = 0; k < map.keyframes.size(); ++k) {
    EXPECT_EQ(back.keyframes[k].name, map.keyframes[k].name);
    EXPECT_EQ(back.keyframes[k].frame_index, map.keyframes[k].frame_index);
    EXPECT_EQ(back.keyframes[k].timestamp, map.keyframes[k].timestamp);
    EXPECT_EQ(back.keyframes[k].pose.t_cw, map.keyframes[k].pose.t_cw);
    ASSERT_EQ(back.keyframes[k].observations.size(), map.keyframes[k].observations.size());
    EXPECT_EQ(back.keyframes[k].observations[4].pixel, map.keyframes[k].observations[4].pixel);
  }
  ASSERT_EQ(back.points.size(), map.points.size());
  EXPECT_EQ(back.points[3].xyz, map.points[3].xyz);
  EXPECT_EQ(back.points[3].rgb, map.points[3].rgb);
  EXPECT_EQ(cv::norm(back.descriptors, map.descriptors, cv::NORM_INF), 0);
  EXPECT_EQ(back.descriptor_point, map.descriptor_point);
  EXPECT_EQ(back.descriptor_keyframe, map.descriptor_keyframe);
  const MapStats s = ComputeStats(back);
  EXPECT_EQ(s.observations, 30u);
  EXPECT_NEAR(s.mean_reprojection_error, 0, 1e-3);
  EXPECT_DOUBLE_EQ(s.mean_track_length, 3);
}

TEST_F(MapFileTest, TheMetricFrameRecordRoundTrips) {
  Map map = SmallMap();
  map.frame.scale_source = ScaleSource::kBoard;
  map.frame.z_up = true;
  map.frame.scale_error = 0.004;
  map.frame.how = "chessboard 9x6 of 0.025 m squares";
  map.frame.from_colmap.scale = 0.37;
  map.frame.from_colmap.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  map.frame.from_colmap.t = {1, -2, 0.5};
  map.camera.focus = 42;
  SaveMap(map, dir_ / kMapFileName);
  EXPECT_EQ(LoadMap(dir_).camera.focus, std::optional<std::int64_t>(42));
  const MapFrame back = LoadMap(dir_).frame;
  EXPECT_EQ(back.scale_source, ScaleSource::kBoard);
  EXPECT_TRUE(back.z_up);
  EXPECT_TRUE(back.metric());
  EXPECT_EQ(back.scale_error, 0.004);
  EXPECT_EQ(back.how, map.frame.how);
  EXPECT_EQ(back.from_colmap.scale, 0.37);
  EXPECT_EQ(back.from_colmap.R, map.frame.from_colmap.R);
  EXPECT_EQ(back.from_colmap.t, map.frame.from_colmap.t);
  EXPECT_STREQ(ToString(ScaleSource::kCameraHeight), "camera height");

  map.frame.from_colmap.R(0, 1) += 0.1;  // no longer a rotation
  try {
    SaveMap(map, dir_ / "bad.arvmap");
    FAIL() << "a frame whose transform is not a similarity was saved";
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("frame record"), std::string::npos) << e.what();
  }
}

// The bytes of `file` with its last `cut` payload bytes cut, then `erase` bytes at `erase_at`
// (offsets in the file), as a file of `version`: the payload size and the checksum (map_file.h's
// FNV-1a over 8-byte words) put back. How the tests make files of the versions before.
std::string AsOlderVersion(const fs::path& file, std::size_t cut, std::size_t erase_at, std::size_t erase,
                           std::uint32_t version) {
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  bytes.resize(bytes.size() - cut);
  bytes.erase(erase_at, erase);
  const std::size_t header = 32;
  const std::uint64_t payload = bytes.size() - header;
  std::uint64_t h = 0xcbf29ce484222325ULL;
  std::size_t i = header;
  for (; i + 8 <= bytes.size(); i += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes.data() + i, 8);
    h = (h ^ word) * 0x100000001b3ULL;
    h ^= h >> 29;
  }
  for (; i < bytes.size(); ++i) h = (h ^ static_cast<unsigned char>(bytes[i])) * 0x100000001b3ULL;
  std::memcpy(bytes.data() + 8, &version, 4);
  std::memcpy(bytes.data() + 16, &payload, 8);
  std::memcpy(bytes.data() + 24, &h, 8);
  return bytes;
}

// The rooms record of a map without rooms: their count, and each keyframe's -1.
std::size_t NoRoomsRecord(const Map& map) { return 8 + 4 * map.keyframes.size(); }

// A map written before the frame record (version 1: the same payload without it and without the
// camera's focus) loads as COLMAP's frame, without rooms.
TEST_F(MapFileTest, AVersionOneFileLoadsInColmapsFrame) {
  Map map = SmallMap();
  SaveMap(map, dir_ / kMapFileName);
  const std::size_t frame_record = 1 + 1 + 8 + 4 + map.frame.how.size() + 8 + 9 * 8 + 3 * 8;
  const std::size_t focus_at = 32 + 4 + 4 + 4 * 8 + 5 * 8;  // after the camera's distortion
  {
    std::ofstream out(dir_ / "v1.arvmap", std::ios::binary);
    out << AsOlderVersion(dir_ / kMapFileName, frame_record + NoRoomsRecord(map), focus_at, 1 + 8, 1);
  }
  const Map back = LoadMap(dir_ / "v1.arvmap");
  EXPECT_FALSE(back.frame.metric());
  EXPECT_FALSE(back.frame.z_up);
  EXPECT_FALSE(back.camera.focus.has_value());
  EXPECT_EQ(back.camera.fx, map.camera.fx);
  EXPECT_EQ(back.keyframes.size(), map.keyframes.size());
  EXPECT_EQ(back.points.size(), map.points.size());
  EXPECT_TRUE(back.rooms.empty());
}

// A venue's rooms: their names and each keyframe's room come back; a map of version 2 (before
// rooms) loads with none.
TEST_F(MapFileTest, TheRoomsRoundTripAndAVersionTwoFileHasNone) {
  Map map = SmallMap();
  map.rooms = {"east", "west"};
  map.keyframes[0].room = 0;
  map.keyframes[1].room = 1;  // keyframe 2 in none (a frame added later by 'map extend')
  SaveMap(map, dir_ / kMapFileName);
  const Map back = LoadMap(dir_);
  EXPECT_EQ(back.rooms, map.rooms);
  ASSERT_EQ(back.keyframes.size(), 3u);
  EXPECT_EQ(back.keyframes[0].room, 0);
  EXPECT_EQ(back.keyframes[1].room, 1);
  EXPECT_EQ(back.keyframes[2].room, -1);

  const Map plain = SmallMap();
  SaveMap(plain, dir_ / kMapFileName);
  {
    std::ofstream out(dir_ / "v2.arvmap", std::ios::binary);
    out << AsOlderVersion(dir_ / kMapFileName, NoRoomsRecord(plain), 0, 0, 2);
  }
  const Map v2 = LoadMap(dir_ / "v2.arvmap");
  EXPECT_TRUE(v2.rooms.empty());
  for (const Keyframe& k : v2.keyframes) EXPECT_EQ(k.room, -1);
  EXPECT_EQ(v2.keyframes.size(), 3u);
}

TEST_F(MapFileTest, AKeyframeInARoomTheMapDoesNotHaveIsRefused) {
  Map map = SmallMap();
  map.rooms = {"east"};
  map.keyframes[2].room = 1;
  try {
    SaveMap(map, dir_ / kMapFileName);
    FAIL() << "a keyframe in room 1 of 1 was saved";
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("keyframe 2 ('frames/2.png') names room 1 of 1"), std::string::npos) << e.what();
  }
  map.keyframes[2].room = 0;
  map.rooms = {""};
  EXPECT_THROW(SaveMap(map, dir_ / kMapFileName), MapError) << "a room without a name";
  EXPECT_FALSE(fs::exists(dir_ / kMapFileName)) << "nothing written";
}

// The room a camera stands in is its nearest keyframe's (keyframes at x = 0, 0.3, 0.6).
TEST(RoomAt, TheNearestKeyframesRoomOrNoneWithoutRooms) {
  Map map = SmallMap();
  EXPECT_EQ(RoomAt(map, Eigen::Vector3d(0.1, 0, 0)), -1) << "a map without rooms";
  map.rooms = {"east", "west"};
  map.keyframes[0].room = 0;
  map.keyframes[1].room = 1;
  map.keyframes[2].room = 1;
  EXPECT_EQ(RoomAt(map, Eigen::Vector3d(0.1, 0, 0)), 0);
  EXPECT_EQ(RoomAt(map, Eigen::Vector3d(0.2, 0.1, -1)), 1);
  map.keyframes[1].room = -1;  // a keyframe without a room is passed over
  EXPECT_EQ(RoomAt(map, Eigen::Vector3d(0.29, 0, 0)), 0);
}

TEST_F(MapFileTest, EveryTruncationIsAClearError) {
  const fs::path file = dir_ / kMapFileName;
  SaveMap(SmallMap(), file);
  const std::vector<char> bytes = Bytes(file);
  const fs::path cut = dir_ / "cut.arvmap";
  for (size_t n = 0; n < bytes.size(); n += std::max<size_t>(1, bytes.size() / 97)) {
    Write(cut, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n)));
    EXPECT_THROW(LoadMap(cut), MapError) << "truncated to " << n << " bytes";
  }
}

TEST_F(MapFileTest, FlippedBytesFailTheChecksum) {
  const fs::path file = dir_ / kMapFileName;
  SaveMap(SmallMap(), file);
  std::vector<char> bytes = Bytes(file);
  bytes[bytes.size() / 2] ^= 0x10;
  Write(file, bytes);
  try {
    LoadMap(file);
    FAIL() << "expected MapError";
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
}

TEST_F(MapFileTest, WrongMagicAndVersionAreNamed) {
  const fs::path file = dir_ / kMapFileName;
  SaveMap(SmallMap(), file);
  std::vector<char> bytes = Bytes(file);
  std::vector<char> other = bytes;
  other[0] = 'X';
  Write(file, other);
  EXPECT_THROW(LoadMap(file), MapError);
  other = bytes;
  other[8] = 99;  // version
  Write(file, other);
  try {
    LoadMap(file);
    FAIL() << "expected MapError";
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("version 99"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadMap(dir_ / "missing"), MapError);
}

TEST_F(MapFileTest, InconsistentMapsAreRefused) {
  Map map = SmallMap();
  map.keyframes[1].observations[2].point = 1000;
  EXPECT_THROW(SaveMap(map, dir_ / "bad.arvmap"), MapError);
  map = SmallMap();
  map.points[0].descriptor_count = 100;
  EXPECT_THROW(ValidateMap(map, "test"), MapError);
  map = SmallMap();
  map.descriptor_keyframe.pop_back();
  EXPECT_THROW(ValidateMap(map, "test"), MapError);
  map = SmallMap();
  map.keyframes[0].observations[0].descriptor = 1;  // a row of keyframe 1
  EXPECT_THROW(ValidateMap(map, "test"), MapError);
  EXPECT_FALSE(fs::exists(dir_ / "bad.arvmap"));
}

// Issue 17's reproducers: loaded without complaint before (the checksum was recomputed).
TEST_F(MapFileTest, ADescriptorRowOutsideItsPointsRangeIsRefused) {
  Map map = SmallMap();
  map.points[0].descriptor_count = 2;  // row 2 still names point 0
  try {
    ValidateMap(map, "test");
    FAIL();
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the descriptor range of its point"), std::string::npos) << e.what();
  }
}

TEST_F(MapFileTest, HugeAndNonFiniteValuesAreRefused) {
  const auto refused = [](void (*mutate)(Map&)) {
    Map map = SmallMap();
    mutate(map);
    try {
      ValidateMap(map, "test");
    } catch (const MapError&) {
      return true;
    }
    return false;
  };
  EXPECT_TRUE(refused([](Map& m) { m.points[3].xyz.x() = 1e30; }));
  EXPECT_TRUE(refused([](Map& m) { m.points[3].xyz.y() = -1e30; }));
  EXPECT_TRUE(refused([](Map& m) { m.points[3].reprojection_error = std::nan(""); }));
  EXPECT_TRUE(refused([](Map& m) { m.keyframes[1].pose.t_cw.z() = 1e30; }));
  EXPECT_TRUE(refused([](Map& m) { m.keyframes[1].timestamp = INFINITY; }));
  EXPECT_TRUE(refused([](Map& m) { m.keyframes[1].observations[0].pixel.x() = 1e30f; }));
  EXPECT_FALSE(refused([](Map&) {}));
}

}  // namespace
}  // namespace arview::map
