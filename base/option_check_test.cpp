#include "base/option_check.h"

#include <gtest/gtest.h>

namespace arview {
namespace {

TEST(OptionNames, AFieldIsCalledByItsPathUnlessTheCallerNamesIt) {
  const OptionNames fields;
  EXPECT_EQ(fields("working_long_side"), "working_long_side");
  EXPECT_EQ(fields.Nested("relocalization")("sift_long_side"), "relocalization.sift_long_side");
  EXPECT_EQ(fields.Nested("relocalization").Nested("pose")("min_inliers"), "relocalization.pose.min_inliers");

  const OptionNames flags({{"working_long_side", "--working-size"}, {"relocalization.sift_long_side", "--sift-size"}});
  EXPECT_EQ(flags("working_long_side"), "--working-size");
  EXPECT_EQ(flags.Nested("relocalization")("sift_long_side"), "--sift-size");
  EXPECT_EQ(flags.Nested("relocalization")("reloc_sift_long_side"), "relocalization.reloc_sift_long_side");
  EXPECT_EQ(flags("sift_long_side"), "sift_long_side") << "a name is for its path only, not any field of that name";
}

TEST(RequireOption, ABadValueIsOneLineNamingTheOptionTheRequirementAndTheValue) {
  EXPECT_NO_THROW(RequireOption(true, "--ratio", "in (0, 1]", 0.8));
  try {
    RequireOption(false, "--ratio", "in (0, 1]", 1.5);
    FAIL() << "no OptionError";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "--ratio must be in (0, 1] (got 1.5)");
  }
  EXPECT_THROW(RequireOption(false, "x", "at least 64", 32), Error) << "an arview::Error, as every module's";
}

}  // namespace
}  // namespace arview
