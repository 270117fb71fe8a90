#include "recordings/recording.h"
#include "recordings/trajectory.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace arview::recordings {
namespace {

TEST(FrameSpec, ListsRangesAndSteps) {
  EXPECT_EQ(ParseFrameSpec("0-6:2", 10), (std::vector<int>{0, 2, 4, 6}));
  EXPECT_EQ(ParseFrameSpec("1,5,7-8", 10), (std::vector<int>{1, 5, 7, 8}));
  EXPECT_EQ(ParseFrameSpec(" 3 , 1 ", 10), (std::vector<int>{1, 3}));
}

// Issue 41: "1," ran one frame while ",1" was refused; an empty item is refused wherever it is.
TEST(FrameSpec, AnEmptyItemIsRefusedAtEitherEndAndInTheMiddle) {
  for (const std::string spec : {"1,", ",1", "1,,2", "1, ", "1,\t"}) {
    try {
      ParseFrameSpec(spec, 10);
      ADD_FAILURE() << "'" << spec << "' was accepted";
    } catch (const RecordingError& e) {
      EXPECT_EQ(std::string(e.what()), "frame spec '" + spec + "': empty item");
    }
  }
}

// Issue 41, found by fuzz_flags's grammar check: every space was removed from an item, so that
// "00 02 2" ran frame 22 and "1 2" frame 12. Spaces and tabs are allowed around items only.
TEST(FrameSpec, ASpaceInsideAnItemIsRefusedNotJoined) {
  for (const std::string spec : {"00 02 2", "1 2", "1- 3", "0-4 :2", "1,\n2", "\v3"}) {
    try {
      ParseFrameSpec(spec, 100);
      ADD_FAILURE() << "'" << spec << "' was accepted";
    } catch (const RecordingError& e) {
      EXPECT_NE(std::string(e.what()).find("is not a frame index"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(ParseFrameSpec("\t1-3:2 ,\t7\t", 10), (std::vector<int>{1, 3, 7}));
  // A step without a range was refused unless it was 1.
  EXPECT_THROW(ParseFrameSpec(" 0:1", 10), RecordingError);
}

}  // namespace
}  // namespace arview::recordings
