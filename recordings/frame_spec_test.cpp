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

}  // namespace
}  // namespace arview::recordings
