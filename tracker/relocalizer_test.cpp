#include "tracker/relocalizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

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
