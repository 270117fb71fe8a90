// A venue's pairs (mapping/venue_pairs.h) on made-up descriptors: random SIFT-like rows, and
// frames of two rooms that see the same things sharing rows up to a little noise.

#include "mapping/venue_pairs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace arview::mapping {
namespace {

cv::Mat RandomRows(int rows, std::mt19937& rng) {
  cv::Mat m(rows, 128, CV_8U);
  std::uniform_int_distribution<int> value(0, 120);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < 128; ++c) m.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(value(rng));
  return m;
}

// The first `count` rows of `from` copied into `to` with noise of +-2.
void Share(const cv::Mat& from, int count, cv::Mat* to, std::mt19937& rng) {
  std::uniform_int_distribution<int> noise(-2, 2);
  for (int r = 0; r < count; ++r)
    for (int c = 0; c < 128; ++c)
      to->at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(std::clamp(from.at<std::uint8_t>(r, c) + noise(rng), 0, 255));
}

bool Holds(const std::vector<ImagePair>& pairs, int a, int b) {
  return std::find(pairs.begin(), pairs.end(), ImagePair{a, b}) != pairs.end();
}

TEST(VenuePairs, FramesOfTwoRoomsThatSeeTheSameThingsArePairedAndNoOthers) {
  std::mt19937 rng(7);
  std::vector<cv::Mat> descriptors;
  for (int i = 0; i < 12; ++i) descriptors.push_back(RandomRows(300, rng));
  Share(descriptors[4], 100, &descriptors[9], rng);   // room 1's frame 9 looks through the door at frame 4's wall
  Share(descriptors[5], 40, &descriptors[11], rng);
  const std::vector<int> room_of{0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1};
  const VenuePairs pairs = PairVenueFrames(room_of, descriptors, ExhaustivePairs, CrossRoomOptions{});
  EXPECT_EQ(pairs.within, 30) << "15 pairs in each room";
  ASSERT_EQ(pairs.pairs.size(), 32u);
  EXPECT_TRUE(Holds(pairs.pairs, 4, 9));
  EXPECT_TRUE(Holds(pairs.pairs, 5, 11));
  for (int k = 0; k < pairs.within; ++k)
    EXPECT_EQ(room_of[pairs.pairs[k].first], room_of[pairs.pairs[k].second]) << "a pair listed within crosses rooms";
  EXPECT_EQ(pairs.across[0][1], 2);
  EXPECT_EQ(pairs.Describe({"hall", "office"}), "30 pairs within rooms, 2 across: hall and office 2");
}

TEST(VenuePairs, ARoomThatSharesNothingIsNamed) {
  std::mt19937 rng(11);
  std::vector<cv::Mat> descriptors;
  for (int i = 0; i < 6; ++i) descriptors.push_back(RandomRows(200, rng));
  Share(descriptors[1], 60, &descriptors[2], rng);
  const VenuePairs pairs = PairVenueFrames({0, 0, 1, 1, 2, 2}, descriptors, ExhaustivePairs, CrossRoomOptions{});
  EXPECT_EQ(pairs.Describe({"hall", "office", "attic"}),
            "3 pairs within rooms, 1 across: hall and office 1; attic shares no frame with the others: it will be "
            "mapped apart, or not at all");
}

TEST(VenuePairs, ARoomsFramesNeedNotFollowEachOtherAndTooFewVotesPairNothing) {
  std::mt19937 rng(3);
  std::vector<cv::Mat> descriptors;
  for (int i = 0; i < 4; ++i) descriptors.push_back(RandomRows(200, rng));
  Share(descriptors[0], 11, &descriptors[1], rng);  // one vote under min_votes
  const VenuePairs pairs = PairVenueFrames({0, 1, 0, 1}, descriptors, ExhaustivePairs, CrossRoomOptions{});
  EXPECT_EQ(pairs.pairs, (std::vector<ImagePair>{{0, 2}, {1, 3}}));
  CrossRoomOptions fewer;
  fewer.min_votes = 10;
  EXPECT_TRUE(Holds(PairVenueFrames({0, 1, 0, 1}, descriptors, ExhaustivePairs, fewer).pairs, 0, 1));
}

TEST(VenuePairs, SequentialWithinRoomsAndEachFramesNeighboursCapped) {
  std::mt19937 rng(5);
  std::vector<cv::Mat> descriptors;
  for (int i = 0; i < 10; ++i) descriptors.push_back(RandomRows(200, rng));
  for (int j = 5; j < 10; ++j) Share(descriptors[0], 50, &descriptors[j], rng);  // frame 0 seen by all of room 1
  CrossRoomOptions one;
  one.neighbours = 1;
  const VenuePairs pairs = PairVenueFrames({0, 0, 0, 0, 0, 1, 1, 1, 1, 1}, descriptors,
                                           [](int n) { return SequentialPairs(n, 1, false); }, one);
  EXPECT_EQ(pairs.within, 8);
  // Each of room 1's frames finds frame 0; frame 0 finds one of them (more, were neighbours larger).
  EXPECT_EQ(pairs.across[0][1], 5);
  CrossRoomOptions none;
  none.neighbours = 0;
  EXPECT_EQ(PairVenueFrames({0, 0, 0, 0, 0, 1, 1, 1, 1, 1}, descriptors, ExhaustivePairs, none).pairs.size(), 20u);
}

TEST(VenuePairs, BadInputsAreOneClearError) {
  const std::vector<cv::Mat> two(2);
  EXPECT_THROW(PairVenueFrames({0}, two, ExhaustivePairs, CrossRoomOptions{}), std::exception);
  EXPECT_THROW(PairVenueFrames({0, -1}, two, ExhaustivePairs, CrossRoomOptions{}), std::exception);
  CrossRoomOptions bad;
  bad.min_votes = 0;
  try {
    bad.Check({});
    FAIL() << "min_votes 0 accepted";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "min_votes must be at least 1 (got 0)");
  }
}

}  // namespace
}  // namespace arview::mapping
