#include "app/cli/output_flags.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "app/cli/commands.h"

namespace arview::app {
namespace {

namespace fs = std::filesystem;

// Issue 57: `replay --stats sd2/` (no such folder) wrote a file named sd2, `--stats ''` was taken
// and ignored; each is now refused before the work starts, naming what is wrong.
TEST(OutputFileCheck, RefusesWhatCannotBecomeTheFile) {
  const fs::path dir = fs::temp_directory_path() / ("arview_output_flags_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "existing");
  const CLI::Validator check = OutputFileCheck();
  for (std::string ok : {(dir / "stats.json").string(), (dir / "existing" / "t.txt").string(), std::string("t.txt")}) {
    EXPECT_EQ(check(ok), "") << ok;
  }
  std::string empty;
  EXPECT_EQ(check(empty), "an empty name: give the file to write");
  std::string slash = (dir / "sd2/").string();
  EXPECT_EQ(check(slash), "'" + slash + "' names a folder (it ends in '/'): give the file to write");
  std::string folder = (dir / "existing").string();
  EXPECT_EQ(check(folder), "'" + folder + "' is a folder: give the file to write");
  std::string missing = (dir / "sd2" / "s.json").string();
  EXPECT_EQ(check(missing), "'" + missing + "': the folder " + (dir / "sd2").string() + " does not exist");
  EXPECT_FALSE(fs::exists(dir / "sd2"));
  fs::remove_all(dir);
}

// Issue 57: `track --stats t.txt --out t.txt` wrote both into one file and lost the trajectory.
TEST(RequireDistinctOutputs, RefusesTwoFlagsNamingOneFile) {
  EXPECT_NO_THROW(RequireDistinctOutputs({{"--out", "t.txt"}, {"--stats", "s.json"}, {"--trajectory", ""}}));
  EXPECT_NO_THROW(RequireDistinctOutputs({{"--out", ""}, {"--stats", ""}}));
  try {
    RequireDistinctOutputs({{"--out", "t.txt"}, {"--stats", "./t.txt"}});
    FAIL() << "one file for two outputs";
  } catch (const CommandError& e) {
    EXPECT_STREQ(e.what(), "--out t.txt and --stats ./t.txt name one file: each output needs its own (the one written "
                           "last would replace the other)");
    EXPECT_EQ(e.code, 2);
  }
}

}  // namespace
}  // namespace arview::app
