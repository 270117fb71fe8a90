// The leaves' merge (mapping/leaf_merge.h) on models made by the test: a room's points seen along
// a camera path, cut into two leaves whose shared frames all stand at one spot, the case where
// COLMAP's model_merger (a similarity fitted to the shared frames' camera centres) fails; and the
// binary model written back byte for byte.

#include "mapping/leaf_merge.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include <Eigen/Geometry>

#include "base/atomic_file.h"
#include "base/input_guard.h"
#include "fuzz/colmap_fixture.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

constexpr double kFocal = 525;

std::string PinholeCamerasBin() {
  std::string bytes;
  fuzz::Put<std::uint64_t>(bytes, 1);
  fuzz::Put<std::uint32_t>(bytes, 1);
  fuzz::Put<std::int32_t>(bytes, 1);  // PINHOLE
  fuzz::Put<std::uint64_t>(bytes, 640);
  fuzz::Put<std::uint64_t>(bytes, 480);
  for (const double v : {kFocal, kFocal, 320.0, 240.0}) fuzz::Put(bytes, v);
  return bytes;
}

// A room's walls (points 6 m apart in x and z, 2.5 m high) seen by `frames` cameras walking around
// its middle and looking outwards; frames `still_from` to `still_from + still_count - 1` stand at
// one spot, turning by a hundredth of a degree each.
struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<calib::Pose> poses;
  std::vector<std::vector<int>> seen;  // per frame, the points it sees: its 2D points in this order
};

Scene RoomScene(int frames, int still_from, int still_count) {
  Scene scene;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> along(-3, 3), up(0, 2.5);
  for (int i = 0; i < 1500; ++i) {
    const double a = along(rng), h = up(rng);
    switch (i % 4) {
      case 0: scene.points.emplace_back(a, h, 3); break;
      case 1: scene.points.emplace_back(a, h, -3); break;
      case 2: scene.points.emplace_back(3, h, a); break;
      default: scene.points.emplace_back(-3, h, a); break;
    }
  }
  for (int f = 0; f < frames; ++f) {
    const bool still = f >= still_from && f < still_from + still_count;
    const int step = still ? still_from : f;
    const double yaw = 0.08 * step + (still ? 1e-4 * (f - still_from) : 0.0);
    const Eigen::Vector3d centre(0.8 * std::cos(0.05 * step), 1.4, 0.8 * std::sin(0.05 * step));
    calib::Pose pose;
    pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())).conjugate();
    pose.t_cw = -(pose.q_cw * centre);
    scene.poses.push_back(pose);
    std::vector<int> seen;
    for (std::size_t p = 0; p < scene.points.size(); ++p) {
      const Eigen::Vector3d c = pose.ToCamera(scene.points[p]);
      if (c.z() < 0.1) continue;
      const double u = kFocal * c.x() / c.z() + 320, v = kFocal * c.y() / c.z() + 240;
      if (u > 0 && u < 640 && v > 0 && v < 480) seen.push_back(static_cast<int>(p));
    }
    scene.seen.push_back(std::move(seen));
  }
  return scene;
}

// The frames [first, last] of `scene` as one leaf's model, moved into its own world by `world`
// (scene → leaf); its point ids start at `first_id`. A point is in the leaf when 2 of its frames see it.
SparseModel LeafOf(const Scene& scene, int first, int last, const Sim3& world, std::uint64_t first_id) {
  SparseModel model;
  model.cameras_bin = PinholeCamerasBin();
  model.camera = calib::Camera::Pinhole(640, 480, kFocal, kFocal, 319.5, 239.5);
  std::map<int, std::vector<TrackElement>> tracks;
  for (int f = first; f <= last; ++f) {
    for (std::size_t k = 0; k < scene.seen[f].size(); ++k)
      tracks[scene.seen[f][k]].push_back({static_cast<std::uint32_t>(f + 1), static_cast<std::uint32_t>(k)});
  }
  std::map<int, std::uint64_t> id_of;
  for (const auto& [p, track] : tracks) {
    if (track.size() < 2) continue;
    ColmapPoint point;
    point.id = first_id + static_cast<std::uint64_t>(p);
    point.point.xyz = world(scene.points[p]);
    point.track = track;
    id_of[p] = point.id;
    model.points.push_back(point);
  }
  for (int f = first; f <= last; ++f) {
    ColmapImage image;
    image.id = static_cast<std::uint32_t>(f + 1);
    image.camera_id = 1;
    image.name = "frames/" + std::to_string(f) + ".png";
    const Rigid3 moved = world.TransformPose(scene.poses[f].ToRigid());
    image.pose.q_cw = moved.rotation;
    image.pose.t_cw = moved.translation;
    for (const int p : scene.seen[f]) {
      const Eigen::Vector3d c = scene.poses[f].ToCamera(scene.points[p]);
      image.xy.emplace_back(kFocal * c.x() / c.z() + 320, kFocal * c.y() / c.z() + 240);
      image.point3d_ids.push_back(id_of.count(p) ? id_of[p] : kInvalidPoint3D);
    }
    model.images.push_back(image);
  }
  return model;
}

Sim3 SomeSimilarity() {
  Sim3 s;
  s.scale = 0.37;
  s.R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  s.t = Eigen::Vector3d(4, -2, 7);
  return s;
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) { return a.angularDistance(b) * 180 / M_PI; }

TEST(LeafMerge, LeavesSharingFramesAtOneSpotMergeOnTheirPoints) {
  // Frames 0-29 and 25-59: the 5 shared frames 25-29 stand at one spot (centres 0 mm apart).
  const Scene scene = RoomScene(60, 25, 5);
  const SparseModel first = LeafOf(scene, 0, 29, Sim3{}, 1);
  const SparseModel second = LeafOf(scene, 25, 59, SomeSimilarity(), 100000);
  LeafAlignment alignment = AlignLeaf(first, second);
  ASSERT_EQ(alignment.problem, "");
  EXPECT_EQ(alignment.report.shared_images, 5);
  EXPECT_GT(alignment.report.pairs, 100);
  EXPECT_EQ(alignment.report.inliers, alignment.report.pairs);
  const Sim3 expected = SomeSimilarity().Inverse();
  EXPECT_NEAR(alignment.report.leaf_to_merged.scale, expected.scale, 1e-9);
  EXPECT_LT((alignment.report.leaf_to_merged.R - expected.R).norm(), 1e-9);

  SparseModel merged = first;
  JoinLeaf(&merged, second, &alignment);
  EXPECT_EQ(merged.images.size(), 60u);
  EXPECT_EQ(alignment.report.images_added, 30);
  EXPECT_GT(alignment.report.points_joined, 0);
  EXPECT_GT(alignment.report.points_added, 0);
  for (const ColmapImage& image : merged.images) {
    const calib::Pose& truth = scene.poses[image.id - 1];
    EXPECT_LT(AngleDeg(image.pose.q_cw, truth.q_cw), 1e-6) << image.name;
    EXPECT_LT((image.pose.Center() - truth.Center()).norm(), 1e-9) << image.name;
  }
  // Every point at its place, each 2D point in one track at most (written and read back: the
  // reader refuses a track that does not refer back), and no point seen twice by the merge.
  std::set<std::pair<std::uint32_t, std::uint32_t>> observations;
  for (const ColmapPoint& p : merged.points) {
    for (const TrackElement& e : p.track) EXPECT_TRUE(observations.emplace(e.image_id, e.point2d_idx).second);
  }
  std::set<std::uint64_t> ids;
  for (const ColmapPoint& p : merged.points) EXPECT_TRUE(ids.insert(p.id).second);
  const fs::path dir = fs::temp_directory_path() / ("arview_leaf_merge_" + std::to_string(::getpid()));
  WriteSparseModel(merged, dir);
  const SparseModel back = ReadSparseModel(dir);
  EXPECT_EQ(back.images.size(), 60u);
  EXPECT_EQ(back.points.size(), merged.points.size());
  fs::remove_all(dir);
}

TEST(LeafMerge, TwoSharedFramesAreTooFewAndSaySo) {
  const Scene scene = RoomScene(40, 100, 0);
  const LeafAlignment alignment = AlignLeaf(LeafOf(scene, 0, 21, Sim3{}, 1), LeafOf(scene, 20, 39, Sim3{}, 100000));
  EXPECT_EQ(alignment.problem, "they share 2 registered frames, a merge needs 3");
}

TEST(LeafMerge, ALeafWhosePointsDisagreeIsNotMerged) {
  const Scene scene = RoomScene(40, 100, 0);
  SparseModel second = LeafOf(scene, 15, 39, Sim3{}, 100000);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.5);
  for (ColmapPoint& p : second.points) p.point.xyz += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const LeafAlignment alignment = AlignLeaf(LeafOf(scene, 0, 19, Sim3{}, 1), second);
  EXPECT_NE(alignment.problem.find("agree under one similarity within 4 px, a merge needs"), std::string::npos)
      << alignment.problem;
}

TEST(LeafMerge, AnObservationTheMergedPosesDoNotExplainIsDropped) {
  const Scene scene = RoomScene(40, 100, 0);
  const SparseModel first = LeafOf(scene, 0, 24, Sim3{}, 1);
  SparseModel second = LeafOf(scene, 20, 39, Sim3{}, 100000);
  // One of the second leaf's own frames, moved 20 px's worth sideways: its observations of
  // points the merge adds from that leaf no longer fit, and are dropped.
  ColmapImage& moved = second.images.back();
  moved.xy[0] += Eigen::Vector2d(20, 0);
  LeafAlignment alignment = AlignLeaf(first, second);
  ASSERT_EQ(alignment.problem, "");
  SparseModel merged = first;
  JoinLeaf(&merged, second, &alignment);
  for (const ColmapImage& image : merged.images) {
    if (image.id == moved.id) {
      EXPECT_EQ(image.point3d_ids[0], kInvalidPoint3D);
    }
  }
}

TEST(SparseModelFiles, AModelReadAndWrittenBackIsByteForByteAsCOLMAPWroteIt) {
  const fs::path dir = fs::temp_directory_path() / ("arview_sparse_model_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  const fuzz::ColmapModelFiles files = fuzz::SmallColmapModel();
  WriteFileAtomically(dir / "in" / "cameras.bin", files.cameras);
  WriteFileAtomically(dir / "in" / "images.bin", files.images);
  WriteFileAtomically(dir / "in" / "points3D.bin", files.points);
  WriteSparseModel(ReadSparseModel(dir / "in"), dir / "out");
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"})
    EXPECT_EQ(ReadFileUpTo(dir / "out" / name, 1 << 20), ReadFileUpTo(dir / "in" / name, 1 << 20)) << name;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview::mapping
