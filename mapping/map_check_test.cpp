// The map's self-check on maps built in the test: a camera moving through a still scene passes;
// a still camera filming a moving object, and a camera that never moved, are flagged.
#include "mapping/map_check.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <fstream>
#include <random>

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

// Keyframes at `centres` looking down +z at a cloud of points 4-6 units away; every point seen by
// every keyframe, observed at its projection. Keypoints: the observations, plus `clutter`
// features that are not map points, at new random places in each frame.
struct Scene {
  map::Map map;
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
};

Scene MovingCameraScene(const std::vector<Eigen::Vector3d>& centres, int points, int clutter, std::uint32_t seed = 5) {
  Scene s;
  s.map.camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    map::Keyframe kf;
    kf.frame_index = static_cast<int>(k);
    kf.pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), centres[k]);
    s.map.keyframes.push_back(kf);
  }
  s.keypoints.resize(centres.size());
  std::uint32_t row = 0;
  for (int i = 0; i < points; ++i) {
    map::MapPoint p;
    p.xyz = Eigen::Vector3d(2 * u(rng), 1.5 * u(rng), 5 + u(rng));
    p.first_descriptor = row;
    p.descriptor_count = static_cast<std::uint32_t>(centres.size());
    s.map.points.push_back(p);
    for (std::uint32_t k = 0; k < centres.size(); ++k, ++row) {
      s.map.descriptor_point.push_back(static_cast<std::uint32_t>(i));
      s.map.descriptor_keyframe.push_back(k);
      const Eigen::Vector2f px = s.map.camera.Project(s.map.keyframes[k].pose.ToCamera(p.xyz)).cast<float>();
      s.map.keyframes[k].observations.push_back({static_cast<std::uint32_t>(i), px, row});
      s.keypoints[k].push_back(px);
    }
  }
  std::uniform_real_distribution<float> x(0, 640), y(0, 480);
  for (auto& frame : s.keypoints)
    for (int c = 0; c < clutter; ++c) frame.emplace_back(x(rng), y(rng));
  return s;
}

std::vector<Eigen::Vector3d> SidewaysPath(int keyframes, double length) {
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < keyframes; ++k) centres.emplace_back(length * k / (keyframes - 1) - length / 2, 0, 0);
  return centres;
}

bool HasWarning(const MapCheck& c, const std::string& text) {
  for (const auto& w : c.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

TEST(MapCheck, ACameraMovingThroughAStillSceneIsNotFlagged) {
  // 1.5 units of sideways travel at 5 units' depth; 400 map points and 1,200 clutter features a frame.
  const Scene s = MovingCameraScene(SidewaysPath(12, 1.5), 400, 1200);
  const MapCheck c = CheckMap(s.map, s.keypoints);
  EXPECT_FALSE(c.flagged()) << DescribeMapCheck(c) << "\n" << (c.warnings.empty() ? "" : c.warnings[0]);
  EXPECT_NEAR(c.explained_fraction, 0.25, 1e-9);
  EXPECT_NEAR(c.path_extent, 1.5, 1e-9);
  EXPECT_NEAR(c.extent_ratio, 1.5 / c.scene_depth, 1e-9);
  EXPECT_GT(c.scene_depth, 4.5);
  EXPECT_LT(c.scene_depth, 5.5);
  EXPECT_GT(c.median_triangulation_deg, 10);
  EXPECT_EQ(c.moving_pairs, 11);
  EXPECT_LT(c.still_fraction, 0.05);  // chance coincidences within 0.5 px
}

// Issue 17's case: the camera never moves, an object is moved in front of it. COLMAP's map is the
// object, with a camera path that is the object's motion; the background's features stay put.
TEST(MapCheck, AStillCameraFilmingAMovingObjectIsFlagged) {
  Scene s = MovingCameraScene(SidewaysPath(12, 1.5), 400, 200);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> x(0, 640), y(0, 480);
  std::normal_distribution<float> jitter(0, 0.05f);  // SIFT positions under sensor noise
  std::vector<Eigen::Vector2f> background(600);
  for (auto& b : background) b = {x(rng), y(rng)};
  for (auto& frame : s.keypoints)
    for (const auto& b : background) frame.push_back(b + Eigen::Vector2f(jitter(rng), jitter(rng)));
  const MapCheck c = CheckMap(s.map, s.keypoints);
  ASSERT_TRUE(c.flagged()) << DescribeMapCheck(c);
  EXPECT_TRUE(HasWarning(c, "looks like a still camera filming a moving object")) << c.warnings[0];
  EXPECT_GT(c.still_fraction, 0.4);
  EXPECT_EQ(c.warnings.size(), 1u) << "the geometry itself looks fine";
}

TEST(MapCheck, ACameraThatNeverMovedIsFlagged) {
  // 2 mm of travel at 5 units' depth (COLMAP's model of a tripod shot fits noise).
  const Scene s = MovingCameraScene(SidewaysPath(12, 0.002), 400, 400);
  const MapCheck c = CheckMap(s.map, s.keypoints);
  EXPECT_TRUE(HasWarning(c, "has a camera path spanning")) << DescribeMapCheck(c);
  EXPECT_TRUE(HasWarning(c, "triangulated from rays a median")) << DescribeMapCheck(c);
  EXPECT_LT(c.extent_ratio, 0.001);
  EXPECT_EQ(c.moving_pairs, 0) << "no pair moves its points by 2 px";
}

TEST(MapCheck, AModelWhosePointsSitNextToItsCamerasIsFlagged) {
  // 10,000 units of path over points 5 units from the cameras: 2,000 x the scene's depth.
  const Scene s = MovingCameraScene(SidewaysPath(12, 10000), 400, 400);
  const MapCheck c = CheckMap(s.map, s.keypoints);
  EXPECT_GT(c.extent_ratio, 1000);
  EXPECT_TRUE(HasWarning(c, "times the scene's depth: its points sit next to the cameras")) << DescribeMapCheck(c);
  // A long walk past its scene is not: 100 units over 5 (a corridor).
  const MapCheck corridor = CheckMap(MovingCameraScene(SidewaysPath(12, 100), 400, 400).map, {});
  EXPECT_FALSE(HasWarning(corridor, "times the scene's depth")) << DescribeMapCheck(corridor);
}

TEST(MapCheck, AMapThatExplainsLittleOfTheFramesIsFlagged) {
  const Scene s = MovingCameraScene(SidewaysPath(12, 1.5), 50, 2000);
  const MapCheck c = CheckMap(s.map, s.keypoints);
  EXPECT_TRUE(HasWarning(c, "explains only 2.4% of the frames' features")) << DescribeMapCheck(c);
}

TEST(MapCheck, TheCheckFileRoundTripsAndAnAbsentOneIsNothing) {
  const fs::path dir = fs::temp_directory_path() / ("arview_map_check_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Scene s = MovingCameraScene(SidewaysPath(12, 0.002), 100, 100);
  const MapCheck c = CheckMap(s.map, s.keypoints);
  WriteMapCheck(c, dir / kMapCheckFileName);
  const auto back = ReadMapCheck(dir / kMapCheckFileName);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->warnings, c.warnings);
  EXPECT_DOUBLE_EQ(back->extent_ratio, c.extent_ratio);
  EXPECT_EQ(DescribeMapCheck(*back), DescribeMapCheck(c));
  EXPECT_FALSE(ReadMapCheck(dir / "absent.json"));
  std::ofstream(dir / "bad.json") << "{\"keyframes\": 3}";
  EXPECT_THROW(ReadMapCheck(dir / "bad.json"), map::MapError);
  fs::remove_all(dir);
}

namespace two_view {

// Keyframes along a path, each turned a little more about a tilted axis (6 degrees apart).
map::Map TurningPath(int keyframes) {
  map::Map m;
  for (int k = 0; k < keyframes; ++k) {
    map::Keyframe kf;
    kf.frame_index = 2 * k;
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d(0.2, 1, 0.1).normalized()));
    kf.pose = calib::Pose::FromCameraToWorld(turn, Eigen::Vector3d(0.3 * k, 0.05 * k, 0));
    m.keyframes.push_back(kf);
  }
  return m;
}

// Every pair's geometry from the true poses, matched by `inliers` features.
std::vector<TwoViewGeometry> TrueGeometries(const map::Map& truth, int inliers) {
  std::vector<TwoViewGeometry> g;
  for (int a = 0; a < static_cast<int>(truth.keyframes.size()); ++a)
    for (int b = a + 1; b < static_cast<int>(truth.keyframes.size()); ++b)
      g.push_back({a, b, inliers, EssentialBetween(truth.keyframes[a].pose, truth.keyframes[b].pose), {}});
  return g;
}

TEST(RotationDisagreementDeg, IsZeroForThePairsOwnRotationAndTheAngleToAnyOther) {
  const map::Map m = TurningPath(4);
  const calib::Pose& a = m.keyframes[0].pose;
  const calib::Pose& b = m.keyframes[3].pose;
  const Eigen::Matrix3d e = EssentialBetween(a, b);
  const Eigen::Matrix3d r_ab = b.R() * a.R().transpose();
  EXPECT_NEAR(*RotationDisagreementDeg(e, r_ab), 0, 1e-6);
  EXPECT_NEAR(*RotationDisagreementDeg(-3.5 * e, r_ab), 0, 1e-6);  // up to scale and sign
  // Off by 12 degrees about an axis across the turn's: the angle of the turn barely changes, the
  // rotation does.
  const Eigen::Matrix3d off = Eigen::AngleAxisd(12 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(*RotationDisagreementDeg(e, off * r_ab), 12, 1e-6);
  // The other direction (E of b to a) is another rotation: the convention matters.
  EXPECT_GT(*RotationDisagreementDeg(e.transpose(), r_ab), 30);
  EXPECT_FALSE(RotationDisagreementDeg(Eigen::Matrix3d::Zero(), r_ab));
  EXPECT_FALSE(RotationDisagreementDeg(Eigen::Matrix3d::Constant(std::nan("")), r_ab));
}

TEST(MapCheck, RotationsThatAgreeWithEveryPairsGeometryAreNotFlagged) {
  const map::Map m = TurningPath(10);
  const MapCheck c = CheckMap(m, {}, TrueGeometries(m, 300));
  EXPECT_EQ(c.two_view_pairs, 45);
  EXPECT_EQ(c.disagreeing_fraction, 0);
  EXPECT_TRUE(c.disagreeing_frames.empty());
  EXPECT_FALSE(HasWarning(c, "two-view geometry"));
  EXPECT_NE(DescribeMapCheck(c).find("0.0% of 45 pairs"), std::string::npos) << DescribeMapCheck(c);
}

// phone-fox's folded default map in miniature: the first keyframes registered at rotations off
// by 15-25 degrees, the rest right. The fold is flagged and its frames named; pairs matched by
// fewer than two_view_min_inliers features are not compared.
TEST(MapCheck, APartOfThePathRegisteredAtWrongRotationsIsFlaggedWithItsFrames) {
  const map::Map truth = TurningPath(10);
  map::Map folded = truth;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Quaterniond off(Eigen::AngleAxisd((15 + 5 * k) * M_PI / 180.0, Eigen::Vector3d::UnitX()));
    folded.keyframes[k].pose.q_cw = off * folded.keyframes[k].pose.q_cw;
  }
  const MapCheck c = CheckMap(folded, {}, TrueGeometries(truth, 300));
  EXPECT_EQ(c.two_view_pairs, 45);
  // The 3 x 7 pairs between the fold and the rest (the 3 within it may agree), none of the rest's.
  EXPECT_GE(c.disagreeing_fraction, 21.0 / 45 - 1e-9);
  EXPECT_LE(c.disagreeing_fraction, 24.0 / 45 + 1e-9);
  EXPECT_EQ(c.disagreeing_frames, (std::vector<int>{0, 2, 4}));
  EXPECT_TRUE(HasWarning(c, "frames 0, 2, 4")) << (c.warnings.empty() ? "" : c.warnings[0]);

  const MapCheck weak = CheckMap(folded, {}, TrueGeometries(truth, 299));
  EXPECT_EQ(weak.two_view_pairs, 0);
  EXPECT_FALSE(HasWarning(weak, "two-view geometry"));
}

// Every pair's geometry from the true poses with its rotation off by 0.05-0.25 degrees (pseudo-random
// axes): what COLMAP's essential matrices look like on real phone frames (phone-fox's median pair:
// 0.15 degrees).
std::vector<TwoViewGeometry> NoisyGeometries(const map::Map& truth, int inliers) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1), size(0.05, 0.25);
  std::vector<TwoViewGeometry> g = TrueGeometries(truth, inliers);
  for (TwoViewGeometry& pair : g) {
    const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Matrix3d noise = Eigen::AngleAxisd(size(rng) * M_PI / 180, axis).toRotationMatrix();
    pair.essential = noise * pair.essential;  // [t]x R -> N [t]x R: the pair's rotation turned by N, near enough
  }
  return g;
}

// phone-fox's second folded default map: frames 0-8 turned 3-10 degrees, under the 10 degrees that
// count a pair as disagreeing. Their own pairs' median shows it; one keyframe off alone does not
// make a fold.
TEST(MapCheck, AMildFoldIsFlaggedByTheKeyframesOwnPairs) {
  const map::Map truth = TurningPath(12);
  const MapCheck right = CheckMap(truth, {}, NoisyGeometries(truth, 300));
  EXPECT_FALSE(Folded(right)) << DescribeMapCheck(right);
  EXPECT_TRUE(right.disagreeing_frames.empty());
  EXPECT_GT(right.median_disagreement_deg, 0.05);
  EXPECT_LT(right.median_disagreement_deg, 0.25);
  // 15 x the median pair, at least 2 degrees
  EXPECT_DOUBLE_EQ(right.keyframe_off_deg, std::max(2.0, 15 * right.median_disagreement_deg));

  map::Map folded = truth;
  for (int k = 0; k < 3; ++k)
    folded.keyframes[k].pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitX())) *
                                    folded.keyframes[k].pose.q_cw;
  const MapCheck c = CheckMap(folded, {}, NoisyGeometries(truth, 300));
  EXPECT_EQ(c.disagreeing_fraction, 0);  // no pair beyond 10 degrees
  EXPECT_EQ(c.disagreeing_frames, (std::vector<int>{0, 2, 4}));
  EXPECT_EQ(c.off_neighbours, 2);
  EXPECT_TRUE(Folded(c));
  EXPECT_TRUE(HasWarning(c, "the pairs of frames 0, 2, 4 disagree by a median of more than"))
      << ::testing::PrintToString(c.warnings);

  map::Map one_off = truth;
  one_off.keyframes[5].pose.q_cw =
      Eigen::Quaterniond(Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitX())) * one_off.keyframes[5].pose.q_cw;
  const MapCheck one = CheckMap(one_off, {}, NoisyGeometries(truth, 300));
  EXPECT_EQ(one.disagreeing_frames, (std::vector<int>{10}));
  EXPECT_FALSE(Folded(one));

  // Two keyframes off apart from each other: poorly matched frames, not a stretch of the path.
  map::Map two_apart = one_off;
  two_apart.keyframes[9].pose.q_cw =
      Eigen::Quaterniond(Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitY())) * two_apart.keyframes[9].pose.q_cw;
  const MapCheck apart = CheckMap(two_apart, {}, NoisyGeometries(truth, 300));
  EXPECT_EQ(apart.disagreeing_frames, (std::vector<int>{10, 18}));
  EXPECT_EQ(apart.off_neighbours, 0);
  EXPECT_FALSE(Folded(apart));
}

// On a small map one pair's essential matrix off by over 10 degrees is over the fraction alone (1 of
// 6 pairs: 17%): not a fold. A second such pair is.
TEST(MapCheck, OnePairOffOnASmallMapIsNotAFold) {
  const map::Map m = TurningPath(4);
  std::vector<TwoViewGeometry> geometry = TrueGeometries(m, 300);
  ASSERT_EQ(geometry.size(), 6u);
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(12 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  geometry[0].essential = turned * geometry[0].essential;
  const MapCheck one = CheckMap(m, {}, geometry);
  EXPECT_NEAR(one.disagreeing_fraction, 1.0 / 6, 1e-9);
  EXPECT_FALSE(Folded(one)) << DescribeMapCheck(one);
  EXPECT_FALSE(HasWarning(one, "two-view geometry"));

  geometry[5].essential = turned * geometry[5].essential;
  const MapCheck two = CheckMap(m, {}, geometry);
  EXPECT_NEAR(two.disagreeing_fraction, 2.0 / 6, 1e-9);
  EXPECT_TRUE(Folded(two)) << DescribeMapCheck(two);
}

// A new mapper run starts from a keyframe that is right, far from the fold, and not one an earlier
// run started from.
TEST(MapCheck, ARetryStartsFromARightKeyframeFarFromTheFold) {
  map::Map folded = TurningPath(12);
  const map::Map truth = folded;
  for (int k = 0; k < 12; ++k) folded.keyframes[k].colmap_image_id = static_cast<std::uint32_t>(100 + k);
  for (int k = 0; k < 3; ++k)
    folded.keyframes[k].pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitX())) *
                                    folded.keyframes[k].pose.q_cw;
  const MapCheck c = CheckMap(folded, {}, NoisyGeometries(truth, 300));
  ASSERT_TRUE(Folded(c));
  // Keyframes 3-11 each agree with their 8 pairs outside the fold: the furthest from it wins.
  EXPECT_EQ(KeyframeToStartFrom(folded, c, {}), 11);
  EXPECT_EQ(KeyframeToStartFrom(folded, c, {111}), 10);
  std::vector<std::uint32_t> all;
  for (int k = 3; k < 12; ++k) all.push_back(static_cast<std::uint32_t>(100 + k));
  EXPECT_FALSE(KeyframeToStartFrom(folded, c, all));  // the fold's own keyframes are never chosen
  EXPECT_FALSE(KeyframeToStartFrom(folded, CheckMap(folded, {}, {}), {}));  // nothing compared
}

// The rendered venue's right map that the check refused (docs/mapping.md, "The map's self-check"):
// walking towards a wall, COLMAP's essential matrices of the pairs there were 2-8 degrees from the
// true rotation while fitting their matches, which a plane holds loosely, and the map's median pair
// 0.09 degrees. Here the extreme case: the matches of a wall alone; the pairs of the last keyframes
// (the walk's end, nearest the wall) have as essential matrix the other motion their homography
// admits, which fits the matches exactly (1.3-7 degrees from the true rotation); the others their
// true one. Each keyframe is matched with the 4 before and after it, as sequential matching does. The map's right poses fit
// every pair's matches too, so no pair is evidence of a fold; a stretch of keyframes turned 4
// degrees does not fit them and is still flagged.
struct WallWalk {
  map::Map map;
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  std::vector<TwoViewGeometry> two_view;
};

// Of the motions (rotation, translation) the homography `h` (normalised coordinates) admits, the
// essential matrix of the one whose rotation is farthest from `r`.
Eigen::Matrix3d TheHomographysOtherMotion(const Eigen::Matrix3d& h, const Eigen::Matrix3d& r) {
  cv::Mat h_cv;
  cv::eigen2cv(h, h_cv);
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(h_cv, cv::Mat::eye(3, 3, CV_64F), rotations, translations, normals);
  double farthest_deg = -1;
  Eigen::Matrix3d essential = Eigen::Matrix3d::Zero();
  for (std::size_t s = 0; s < rotations.size(); ++s) {
    Eigen::Matrix3d rs;
    Eigen::Vector3d ts;
    cv::cv2eigen(rotations[s], rs);
    cv::cv2eigen(translations[s], ts);
    const double deg = Eigen::AngleAxisd(rs.transpose() * r).angle() * 180 / M_PI;
    if (deg > farthest_deg) farthest_deg = deg, essential = EssentialBetween({}, calib::Pose::FromRt(rs, ts));
  }
  return essential;
}

WallWalk WalkTowardsAWall(int keyframes, int first_at_the_wall) {
  WallWalk w;
  w.map.camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  for (int k = 0; k < keyframes; ++k) {
    map::Keyframe kf;
    kf.frame_index = 2 * k;
    const Eigen::Quaterniond yaw(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitY()));
    kf.pose = calib::Pose::FromCameraToWorld(yaw, Eigen::Vector3d(0.1 * k, 0.02 * k, 0.3 * k));
    w.map.keyframes.push_back(kf);
  }
  // The wall z = 10: 600 points, each a keypoint of every keyframe; a pair matches those both see.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> across(-2, 5), up(-2, 2);
  std::vector<Eigen::Vector3d> wall;
  for (int i = 0; i < 600; ++i) wall.emplace_back(across(rng), up(rng), 10);
  w.keypoints.resize(keyframes);
  for (int k = 0; k < keyframes; ++k)
    for (const Eigen::Vector3d& p : wall)
      w.keypoints[k].push_back(w.map.camera.Project(w.map.keyframes[k].pose.ToCamera(p)).cast<float>());
  for (int a = 0; a < keyframes; ++a)
    for (int b = a + 1; b < keyframes && b <= a + 4; ++b) {
      std::vector<std::array<std::uint32_t, 2>> matches;
      for (std::uint32_t i = 0; i < wall.size(); ++i)
        if (w.map.camera.InImage(w.keypoints[a][i].cast<double>()) && w.map.camera.InImage(w.keypoints[b][i].cast<double>()))
          matches.push_back({i, i});
      const calib::Pose& pa = w.map.keyframes[a].pose;
      const calib::Pose& pb = w.map.keyframes[b].pose;
      Eigen::Matrix3d essential = EssentialBetween(pa, pb);
      if (a >= first_at_the_wall) {
        const Eigen::Matrix3d r = pb.R() * pa.R().transpose();
        const Eigen::Vector3d n = pa.R() * Eigen::Vector3d::UnitZ();  // the wall in camera a: n^T x = d
        const double d = n.dot(pa.ToCamera(wall[0]));
        essential = TheHomographysOtherMotion(r + (pb.t_cw - r * pa.t_cw) * n.transpose() / d, r);
      }
      w.two_view.push_back({a, b, static_cast<int>(matches.size()), essential, matches});
    }
  return w;
}

TEST(MapCheck, PairsWhoseMatchesTheMapsPosesFitAreNoEvidenceOfAFold) {
  const WallWalk w = WalkTowardsAWall(20, 14);
  ASSERT_EQ(w.two_view.size(), 70u);
  for (const TwoViewGeometry& g : w.two_view) ASSERT_GE(g.inliers, 300);

  // The essential matrices' rotations alone (no matches): the right map looks folded at the wall.
  std::vector<TwoViewGeometry> rotations_only = w.two_view;
  for (TwoViewGeometry& g : rotations_only) g.matches.clear();
  const MapCheck alone = CheckMap(w.map, w.keypoints, rotations_only);
  EXPECT_EQ(alone.fitted_pairs, 0);
  EXPECT_LT(alone.median_disagreement_deg, 0.01);  // most pairs' essential matrices are exact
  EXPECT_TRUE(Folded(alone)) << DescribeMapCheck(alone);
  ASSERT_FALSE(alone.disagreeing_frames.empty());
  EXPECT_GE(alone.disagreeing_frames.front(), 28);  // keyframe 14 on: the wall's pairs

  const MapCheck right = CheckMap(w.map, w.keypoints, w.two_view);
  EXPECT_EQ(right.two_view_pairs, 70);
  EXPECT_EQ(right.fitted_pairs, 70);
  EXPECT_TRUE(right.disagreeing_frames.empty());
  EXPECT_FALSE(Folded(right)) << DescribeMapCheck(right);
  EXPECT_NE(DescribeMapCheck(right).find("70 fitted by the map's poses"), std::string::npos) << DescribeMapCheck(right);

  // Keyframes 0-2 turned 4, 6 and 8 degrees: their pairs do not fit their matches.
  map::Map folded = w.map;
  for (int k = 0; k < 3; ++k)
    folded.keyframes[k].pose.q_cw =
        Eigen::Quaterniond(Eigen::AngleAxisd((4 + 2 * k) * M_PI / 180, Eigen::Vector3d::UnitX())) *
        folded.keyframes[k].pose.q_cw;
  const MapCheck c = CheckMap(folded, w.keypoints, w.two_view);
  EXPECT_EQ(c.fitted_pairs, 70 - 3 - 9);  // all but the 3 within the fold and the 9 between it and the rest
  EXPECT_EQ(c.disagreeing_frames, (std::vector<int>{0, 2, 4}));
  EXPECT_TRUE(Folded(c)) << DescribeMapCheck(c);
}

TEST(MapCheck, TheTwoViewFiguresSurviveTheCheckFile) {
  const map::Map truth = TurningPath(6);
  map::Map folded = truth;
  folded.keyframes[0].pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())) * folded.keyframes[0].pose.q_cw;
  const MapCheck c = CheckMap(folded, {}, TrueGeometries(truth, 300));
  const fs::path file = fs::temp_directory_path() / ("arview_check_two_view_" + std::to_string(::getpid()) + ".json");
  WriteMapCheck(c, file);
  const std::optional<MapCheck> back = ReadMapCheck(file);
  fs::remove(file);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->two_view_pairs, c.two_view_pairs);
  EXPECT_DOUBLE_EQ(back->disagreeing_fraction, c.disagreeing_fraction);
  EXPECT_EQ(back->disagreeing_frames, c.disagreeing_frames);
  EXPECT_DOUBLE_EQ(back->median_disagreement_deg, c.median_disagreement_deg);
  EXPECT_DOUBLE_EQ(back->keyframe_off_deg, c.keyframe_off_deg);
  EXPECT_EQ(back->off_neighbours, c.off_neighbours);
  EXPECT_EQ(back->fitted_pairs, c.fitted_pairs);
  EXPECT_EQ(back->warnings, c.warnings);
}

}  // namespace two_view
}  // namespace
}  // namespace arview::mapping
