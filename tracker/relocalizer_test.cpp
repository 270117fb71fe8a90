#include "tracker/relocalizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"
#include "tracker/test_scene.h"

namespace arview::tracker {
namespace {

// A descriptor: `base` everywhere, `bumps` bytes from `at` raised by `by` (distance by * sqrt(bumps)).
cv::Mat Descriptor(int base, int at = 0, int bumps = 0, int by = 0) {
  cv::Mat row(1, 128, CV_8U, cv::Scalar(base));
  for (int i = at; i < at + bumps; ++i) row.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(base + by);
  return row;
}

// A map of keyframes and points whose observations carry the given descriptors: each entry is
// (keyframe, point, descriptor).
struct Observed {
  int keyframe;
  int point;
  cv::Mat descriptor;
};

map::Map MapOf(int keyframes, int points, const std::vector<Observed>& observed) {
  map::Map map;
  map.keyframes.resize(static_cast<size_t>(keyframes));
  map.points.resize(static_cast<size_t>(points));
  map.descriptors = cv::Mat(0, 128, CV_8U);
  for (const Observed& o : observed) {
    const auto row = static_cast<std::uint32_t>(map.descriptors.rows);
    map.descriptors.push_back(o.descriptor);
    map.descriptor_point.push_back(static_cast<std::uint32_t>(o.point));
    map.descriptor_keyframe.push_back(static_cast<std::uint32_t>(o.keyframe));
    map::KeyframeObservation observation;
    observation.point = static_cast<std::uint32_t>(o.point);
    observation.descriptor = row;
    map.keyframes[o.keyframe].observations.push_back(observation);
  }
  return map;
}

Features FeaturesOf(const std::vector<cv::Mat>& descriptors) {
  Features f;
  f.descriptors = cv::Mat(0, 128, CV_8U);
  for (size_t i = 0; i < descriptors.size(); ++i) {
    f.keypoints.emplace_back(cv::Point2f(static_cast<float>(i), 0.f), 2.f);
    f.descriptors.push_back(descriptors[i]);
  }
  return f;
}

map::DescriptorIndex ExactIndex(const map::Map& map) {
  map::IndexParams params;
  params.kind = map::IndexKind::kLinear;
  return map::DescriptorIndex(map.descriptors, params);
}

// One place seen by two keyframes as two map points (COLMAP split its track, or a façade repeats
// it): against the whole map its nearest other point is as near, and the global ratio test
// drops it; each keyframe holds it once, so matched keyframe by keyframe it passes, and gives
// that keyframe's point.
TEST(MatchToKeyframes, APlaceTheMapHoldsTwiceMatchesInEachKeyframe) {
  const map::Map map = MapOf(2, 4, {{0, 0, Descriptor(10, 0, 16, 20)},   // the place in keyframe 0
                                    {1, 1, Descriptor(10, 0, 16, 24)},   // the same place, another point
                                    {0, 2, Descriptor(10, 64, 16, 60)},  // other keypoints, far
                                    {1, 3, Descriptor(10, 80, 16, 60)}});
  const map::DescriptorIndex index = ExactIndex(map);
  const Features frame = FeaturesOf({Descriptor(10, 0, 16, 22)});  // 8 from either

  EXPECT_TRUE(MatchToMap(frame, map, index, MatchOptions{}).empty());

  std::vector<MapMatch> matches = MatchToKeyframes(frame, map, index, {0, 1}, 4, 0.8);
  ASSERT_EQ(matches.size(), 2u);
  std::sort(matches.begin(), matches.end(), [](const MapMatch& a, const MapMatch& b) { return a.point < b.point; });
  EXPECT_EQ(matches[0].keypoint, 0);
  EXPECT_EQ(matches[0].point, 0u);
  EXPECT_EQ(matches[1].point, 1u);
  // Only the keyframes asked for.
  const std::vector<MapMatch> only_second = MatchToKeyframes(frame, map, index, {1}, 4, 0.8);
  ASSERT_EQ(only_second.size(), 1u);
  EXPECT_EQ(only_second[0].point, 1u);
}

// Twice in one keyframe (a repeated ornament within the photo) is ambiguous there too.
TEST(MatchToKeyframes, TwoLikeKeypointsOfOneKeyframeFailItsRatioTest) {
  const map::Map map = MapOf(1, 3, {{0, 0, Descriptor(10, 0, 16, 20)},
                                    {0, 1, Descriptor(10, 0, 16, 24)},
                                    {0, 2, Descriptor(10, 64, 16, 60)}});
  const map::DescriptorIndex index = ExactIndex(map);
  EXPECT_TRUE(MatchToKeyframes(FeaturesOf({Descriptor(10, 0, 16, 22)}), map, index, {0}, 4, 0.8).empty());
  // A keypoint clearly nearer one of them passes.
  const std::vector<MapMatch> clear = MatchToKeyframes(FeaturesOf({Descriptor(10, 64, 16, 58)}), map, index, {0}, 4, 0.8);
  ASSERT_EQ(clear.size(), 1u);
  EXPECT_EQ(clear[0].point, 2u);
}

// A keyframe with one row among the k neighbours: its second nearest lies beyond the last of them,
// and the last one's distance bounds it.
TEST(MatchToKeyframes, TheLastNeighbourBoundsASecondNotAmongThem) {
  const map::Map map = MapOf(2, 4, {{0, 0, Descriptor(10, 0, 16, 20)},    // keyframe 0: the match
                                    {1, 1, Descriptor(10, 0, 16, 30)},    // keyframe 1: nearer rows
                                    {1, 2, Descriptor(10, 0, 16, 32)},
                                    {0, 3, Descriptor(10, 64, 16, 100)}});  // keyframe 0's second, far
  const map::DescriptorIndex index = ExactIndex(map);
  // The keypoint is 8 from keyframe 0's row, 32 and 40 from keyframe 1's.
  const Features frame = FeaturesOf({Descriptor(10, 0, 16, 22)});
  // k = 2: keyframe 0's second is not among them; the last neighbour (32) bounds it: 8 <= 0.8 * 32.
  const std::vector<MapMatch> two = MatchToKeyframes(frame, map, index, {0}, 2, 0.8);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].point, 0u);
  EXPECT_NEAR(two[0].distance, 8.f, 1e-3);
  // A ratio the bound does not clear drops it.
  EXPECT_TRUE(MatchToKeyframes(frame, map, index, {0}, 2, 0.1).empty());
}

// The graffiti plane's map makes every keypoint of every keyframe its own point, so each place seen
// by several keyframes is several points: the global ratio test drops it, matching keyframe by
// keyframe keeps it. A view between the keyframes is posed on more inliers, as exactly.
TEST(Relocalizer, MatchingKeyframeByKeyframeKeepsThePlacesTheMapHoldsSeveralTimes) {
  ARVIEW_REQUIRE_DATA_PATH(testing::kGraffitiTexture, "Debian package opencv-doc");
  const testing::GraffitiPlane* plane = testing::SharedGraffitiPlane();
  ASSERT_NE(plane, nullptr);
  const map::DescriptorIndex index(plane->map.descriptors);
  const calib::Pose truth = testing::LookAt({0.12, 0.06, -0.82}, {0.02, 0, 0});
  const cv::Mat frame = plane->world.Render(truth);

  RelocalizerOptions global_only;
  global_only.keyframe_matching = 0;
  RelocalizerOptions by_keyframe;
  by_keyframe.keyframe_matching = 5;
  const RelocalizationResult before = Relocalizer(plane->map, plane->map.camera, index, global_only).Relocalize(frame);
  const RelocalizationResult after = Relocalizer(plane->map, plane->map.camera, index, by_keyframe).Relocalize(frame);
  ASSERT_TRUE(before.pose.ok) << before.pose.reason;
  ASSERT_TRUE(after.pose.ok) << after.pose.reason;
  EXPECT_GT(after.matches, before.matches);
  EXPECT_GT(after.inliers.points.size(), before.inliers.points.size() * 3 / 2)
      << before.inliers.points.size() << " inliers matched globally, " << after.inliers.points.size() << " by keyframe";
  EXPECT_LT((after.pose.pose.Center() - truth.Center()).norm(), 0.002);
  EXPECT_LT(testing::RotationErrorDeg(after.pose.pose, truth), 0.1);
  // Each keypoint is followed once, whatever points it matched in the keyframes: no more followed
  // than the frame has keypoints, fewer than the pose's inliers.
  EXPECT_LE(after.inliers.points.size(), static_cast<size_t>(after.keypoints));
  EXPECT_LE(static_cast<int>(after.inliers.points.size()), after.pose.stats.inliers);
  std::printf("inliers: %zu matched globally, %zu by keyframe (pose on %d)\n", before.inliers.points.size(),
              after.inliers.points.size(), after.pose.stats.inliers);
}

TEST(KeyframesSeeingMost, MostFirstTiesByIndexNoneLeftOut) {
  const map::Map map = MapOf(4, 5, {{0, 0, Descriptor(0)}, {0, 1, Descriptor(0)},
                                    {1, 2, Descriptor(0)},
                                    {2, 0, Descriptor(0)}, {2, 1, Descriptor(0)}, {2, 2, Descriptor(0)},
                                    {3, 4, Descriptor(0)}});
  EXPECT_EQ(KeyframesSeeingMost(map, {0, 1, 2}, 10), (std::vector<int>{2, 0, 1}));
  EXPECT_EQ(KeyframesSeeingMost(map, {0, 1, 2}, 2), (std::vector<int>{2, 0}));
  EXPECT_EQ(KeyframesSeeingMost(map, {2}, 10), (std::vector<int>{1, 2}));  // a tie: by index
  EXPECT_TRUE(KeyframesSeeingMost(map, {3}, 10).empty());                  // a point no keyframe sees
  EXPECT_TRUE(KeyframesSeeingMost(map, {0, 1}, 0).empty());
}

}  // namespace
}  // namespace arview::tracker
