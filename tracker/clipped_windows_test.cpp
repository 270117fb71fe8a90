#include "tracker/clipped_windows.h"

#include <gtest/gtest.h>

#include <vector>

#include "base/error.h"

namespace arview::tracker {
namespace {

// A textured 100x100 frame whose right half is clipped white (a lamp's light on a raised exposure).
cv::Mat HalfClipped() {
  cv::Mat gray(100, 100, CV_8U);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) gray.at<std::uint8_t>(y, x) = x >= 50 ? 255 : static_cast<std::uint8_t>((x * 7 + y * 13) % 200);
  return gray;
}

ClippedWindowOptions Share(double share) {
  ClippedWindowOptions o;
  o.max_share = share;
  return o;
}

TEST(ClippedWindows, ATrackInsideTheWhiteIsDroppedOneBesideItIsKept) {
  const std::vector<Eigen::Vector2d> tracks = {{20, 50}, {80, 50}, {48, 50}, {53, 50}};
  const std::vector<bool> clipped = MostlyClipped(HalfClipped(), tracks, 11, Share(0.5));
  // {48, 50}: its one pixel is textured and 4 of its window's 11 columns are white; {53, 50}: its
  // pixel is white but 2 columns of the window textured, so 9 of 11 white.
  EXPECT_EQ(clipped, (std::vector<bool>{false, true, false, true}));
}

TEST(ClippedWindows, OffByDefaultAndAtTheImagesEdgeTheWindowIsClamped) {
  const std::vector<Eigen::Vector2d> tracks = {{99, 0}, {0, 99}};
  EXPECT_EQ(MostlyClipped(HalfClipped(), tracks, 11, {}), (std::vector<bool>{false, false}));
  EXPECT_EQ(MostlyClipped(HalfClipped(), tracks, 11, Share(0.5)), (std::vector<bool>{true, false}));
}

TEST(ClippedWindows, OptionsCheckThemselves) {
  EXPECT_THROW(Share(0).Check(), OptionError);
  ClippedWindowOptions o;
  o.clip_grey = 0;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_NO_THROW(ClippedWindowOptions{}.Check());
}

}  // namespace
}  // namespace arview::tracker
