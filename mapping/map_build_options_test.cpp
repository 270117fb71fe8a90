#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "mapping/colmap_pipeline.h"

namespace arview::mapping {
namespace {

std::string Refusal(const MapBuildOptions& options, const OptionNames& names = {}) {
  try {
    options.Check(names);
  } catch (const OptionError& e) {
    return e.what();
  }
  return "(nothing refused)";
}

TEST(MapBuildOptionsCheck, TheDefaultsAndTheFastPresetPass) {
  MapBuildOptions options;
  EXPECT_NO_THROW(options.Check());
  options.UseFastPreset();
  EXPECT_NO_THROW(options.Check());
}

TEST(MapBuildOptionsCheck, ABadValueIsRefusedNamingTheField) {
  MapBuildOptions o;
  o.threads = -2;
  EXPECT_EQ(Refusal(o), "threads must be -1 (all cores) or more (got -2)");
  o = {};
  o.ba_global_ratio = 1;
  EXPECT_EQ(Refusal(o), "ba_global_ratio must be above 1 (got 1)");
  o = {};
  o.fold_retries = -1;
  EXPECT_EQ(Refusal(o, OptionNames({{"fold_retries", "--fold-retries"}, {"threads", "--threads"}})), "--fold-retries must be 0 or more (got -1)");
  o = {};
  o.gap_retry_angle_deg = 1.5;
  EXPECT_EQ(Refusal(o), "gap_retry_angle_deg must be 0 (no retry) to below 1.5 (degrees) (got 1.5)");
  o = {};
  o.gap_retry_min_frames = 0;
  EXPECT_EQ(Refusal(o), "gap_retry_min_frames must be at least 1 (got 0)");
  o = {};
  o.colmap = "";
  EXPECT_EQ(Refusal(o), "colmap: an empty name: give the COLMAP executable");
  o = {};
  o.scale.from = ScaleFrom::kBoard;
  o.scale.board.square = 0;
  EXPECT_EQ(Refusal(o), "scale.board.square must be above 0 (metres) (got 0)");
}

// BuildMap checks its options before it reads the recording or writes anything.
TEST(MapBuildOptionsCheck, BuildMapRefusesBadOptionsBeforeWritingAnything) {
  MapBuildOptions o;
  o.max_frames = -1;
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "arview_map_options_check";
  std::filesystem::remove_all(out);
  try {
    BuildMap(recordings::Recording{}, out, o);
    ADD_FAILURE() << "BuildMap took max_frames -1";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "mapping.max_frames must be 0 (no cap) or more (got -1)");
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace arview::mapping
