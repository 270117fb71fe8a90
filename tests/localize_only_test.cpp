// Localize only, never change the map (issue 40): `arview track`, `replay` and `run` read the map
// folder and write nothing into it, and a read-only map folder works. The map: the graffiti plane
// the tracker's tests map (tracker/test_planar_scene.h) saved as `arview map` leaves a folder
// (map.arvmap, keyframes.txt, map.png, the keyframes' images in images/); the recording: views
// of the plane rendered along a path, the first of them darkened, so that the commands localize,
// track, lose frames and give their causes, reading the keyframes' images.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "map/map_file.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/graffiti_map.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;

// What a folder holds, entry by entry: its kind, size, content hash and modification time (in
// nanoseconds). A folder's own time changes when an entry is added, renamed or removed in it,
// so a temporary file created and removed again shows too.
struct Entry {
  bool folder = false;
  std::uintmax_t size = 0;
  std::uint64_t hash = 0;
  std::int64_t mtime_ns = 0;
  bool operator==(const Entry&) const = default;
};
using Snapshot = std::map<std::string, Entry>;

std::uint64_t Fnv1a(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::uint64_t h = 14695981039346656037ull;
  for (char c; in.get(c);) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

Entry Describe(const fs::path& path) {
  struct stat st {};
  EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
  Entry e;
  e.folder = S_ISDIR(st.st_mode);
  e.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  if (!e.folder) {
    e.size = static_cast<std::uintmax_t>(st.st_size);
    e.hash = Fnv1a(path);
  }
  return e;
}

Snapshot Take(const fs::path& root) {
  Snapshot s = {{".", Describe(root)}};
  for (const auto& item : fs::recursive_directory_iterator(root)) {
    s[fs::relative(item.path(), root).string()] = Describe(item.path());
  }
  return s;
}

// The differences, one a line: "added x", "removed x", "changed x".
std::string Differences(const Snapshot& before, const Snapshot& after) {
  std::string out;
  for (const auto& [name, entry] : after) {
    const auto it = before.find(name);
    if (it == before.end()) out += "added " + name + "\n";
    else if (!(it->second == entry)) out += "changed " + name + "\n";
  }
  for (const auto& [name, entry] : before) {
    if (!after.contains(name)) out += "removed " + name + "\n";
  }
  return out;
}

class LocalizeOnly : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(tracker::testing::kGraffitiTexture, "Debian package opencv-doc");
    ASSERT_TRUE(fs::exists(ARVIEW_FAKE_V4L2_LIBRARY)) << ARVIEW_FAKE_V4L2_LIBRARY;
    dir_ = fs::temp_directory_path() / ("arview_localize_only_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    testing::WriteGraffitiMapFolder(dir_ / "map");
    testing::WriteGraffitiViews(dir_ / "views");
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    for (const auto& item : fs::recursive_directory_iterator(dir_, ec)) {
      fs::permissions(item.path(), fs::perms::owner_write, fs::perm_options::add, ec);
    }
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // track, replay and run against `map`, each leaving it as it was; each localizes the views
  // and gives the darkened ones their cause.
  void ExpectEveryCommandLeavesTheMapAsItWas(const fs::path& map, const std::string& label) {
    const fs::path views = dir_ / "views", out = dir_ / ("out_" + label);
    fs::create_directories(out);
    ::setenv("ARVIEW_CACHE_DIR", (dir_ / "cache").c_str(), 1);  // the descriptor index's cache, outside the map
    const std::vector<std::vector<std::string>> commands = {
        {"track", views.string(), "--map", map.string(), "--out", (out / "track.txt").string(), "--stats",
         (out / "track.json").string()},
        {"replay", views.string(), "--map", map.string(), "--out", "null", "--hud", "--stats",
         (out / "replay.json").string(), "--trajectory", (out / "replay.txt").string()}};
    for (const auto& args : commands) {
      const Snapshot before = Take(map);
      const CommandResult r = testing::RunArview(args);
      EXPECT_EQ(r.exit_code, 0) << label << " " << args[0] << ": " << r.err;
      EXPECT_EQ(Differences(before, Take(map)), "") << label << " " << args[0] << " changed the map folder";
      EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(localized 1[0-8]/24|1[0-8] localized)"))) << args[0] << r.out;
      EXPECT_NE(r.out.find("too dark (e.g. brightness"), std::string::npos) << args[0] << ": " << r.out;
    }
    const Snapshot before = Take(map);
    // Relocalized in line, not on the tracker's worker: the worker runs at nice +10, and on a
    // loaded machine (load 7 in release, and under TSan) its first relocalization had not
    // finished when the run was stopped, so nothing was localized. What is checked here is the
    // map folder, which neither way writes.
    const CommandResult live = testing::RunWithEmulatedCamera(
        {"run", "--device", testing::kEmulatedCamera, "--map", map.string(), "--out", "null", "--stats",
         (out / "run.json").string(), "--tracking-worker", "off"},
        {{"ARVIEW_FAKE_CAMERA_RECORDING", views.string()}}, out, {0, 0}, 4.0 * testing::kSanitizerSlowdown);
    EXPECT_EQ(live.exit_code, 0) << label << " run: " << live.err;
    EXPECT_EQ(Differences(before, Take(map)), "") << label << " run changed the map folder";
    EXPECT_TRUE(std::regex_search(live.out, std::regex(R"([1-9]\d* localized)"))) << live.out;
    ::unsetenv("ARVIEW_CACHE_DIR");
    EXPECT_TRUE(fs::exists(dir_ / "cache" / "descriptor-index")) << "the index is cached, outside the map";
  }

  fs::path dir_;
};

TEST_F(LocalizeOnly, TrackReplayAndRunLeaveTheMapFolderByteIdentical) {
  ExpectEveryCommandLeavesTheMapAsItWas(dir_ / "map", "writable");
}

// Permission bits stop a write by anyone but root. Tests may run as root, whom they do not stop:
// then what shows a write is the comparison above (every file's bytes and time, every folder's
// time), which the read-only copy goes through as well.
TEST_F(LocalizeOnly, AReadOnlyMapFolderWorks) {
  const fs::path map = dir_ / "read-only-map";
  fs::copy(dir_ / "map", map, fs::copy_options::recursive);
  for (const auto& item : fs::recursive_directory_iterator(map)) {
    fs::permissions(item.path(), fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                    fs::perm_options::remove);
  }
  fs::permissions(map, fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write, fs::perm_options::remove);
  if (::geteuid() == 0) {
    std::cout << "[ root ] the permission bits do not stop root's writes: the snapshot comparison shows any\n";
  } else {
    EXPECT_FALSE(std::ofstream(map / "probe").is_open()) << "the copy is read-only";
  }
  ExpectEveryCommandLeavesTheMapAsItWas(map, "read-only");
}

// What the two tests above rest on: the comparison sees a file rewritten with the same bytes (its
// time), and one written and removed again (the folder's time), as well as a changed byte.
TEST_F(LocalizeOnly, TheComparisonSeesEveryKindOfWrite) {
  const fs::path map = dir_ / "map";
  Snapshot before = Take(map);
  const std::string keyframes = testing::ReadWholeFile((map / "keyframes.txt").string());
  ::usleep(20000);  // a later time stamp than the file's
  std::ofstream(map / "keyframes.txt", std::ios::binary) << keyframes;
  EXPECT_EQ(Differences(before, Take(map)), "changed keyframes.txt\n");
  before = Take(map);
  std::ofstream(map / "images" / "cache.tmp") << "x";
  fs::remove(map / "images" / "cache.tmp");
  EXPECT_EQ(Differences(before, Take(map)), "changed images\n");
  before = Take(map);
  std::ofstream(map / "keyframes.txt", std::ios::binary) << keyframes << " ";
  EXPECT_EQ(Differences(before, Take(map)), "changed keyframes.txt\n");
}

}  // namespace
}  // namespace arview
