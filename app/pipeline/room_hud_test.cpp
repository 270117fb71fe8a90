#include "app/pipeline/room_hud.h"

#include <gtest/gtest.h>

namespace arview::app {
namespace {

using Lines = std::vector<std::string>;

TEST(RoomHud, AMapWithoutRoomsShowsNoRoomLines) {
  RoomHud hud;
  EXPECT_EQ(hud.Update("", 0.0), Lines{});
  EXPECT_EQ(hud.Update("", 1.0), Lines{});
}

TEST(RoomHud, TheFirstRoomIsShownWithoutAChangeNote) {
  RoomHud hud;
  EXPECT_EQ(hud.Update("east", 0.0), Lines{"room: east"});
  EXPECT_EQ(hud.Update("east", 0.5), Lines{"room: east"});
}

TEST(RoomHud, AChangeIsNotedForThreeSecondsOfTheFramesTime) {
  RoomHud hud;
  hud.Update("east", 10.0);
  const Lines changed = {"room: west", "room changed: east -> west"};
  EXPECT_EQ(hud.Update("west", 11.0), changed);
  EXPECT_EQ(hud.Update("west", 13.9), changed);
  EXPECT_EQ(hud.Update("west", 14.0), Lines{"room: west"});
}

TEST(RoomHud, ALostFrameNamesTheLastRoomAndTheNextRoomCountsAsAChange) {
  RoomHud hud;
  hud.Update("east", 0.0);
  EXPECT_EQ(hud.Update("", 5.0), Lines{"room: none while lost (last in east)"});
  EXPECT_EQ(hud.Update("east", 6.0), Lines{"room: east"});  // found again where it was
  hud.Update("", 7.0);
  EXPECT_EQ(hud.Update("hall", 8.0), (Lines{"room: hall", "room changed: east -> hall"}));
}

TEST(RoomHud, GoingBackThroughTheDoorIsAChangeToo) {
  RoomHud hud;
  hud.Update("east", 0.0);
  hud.Update("west", 1.0);
  EXPECT_EQ(hud.Update("east", 1.5), (Lines{"room: east", "room changed: west -> east"}));
}

}  // namespace
}  // namespace arview::app
