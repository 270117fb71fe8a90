#pragma once
// templeRing's 24 even frames mapped with COLMAP once for every test process of a user: the map
// lives in $TMPDIR/arview_temple_map_test_<uid>/map under a file lock; the first process builds
// it, every other one re-uses it through BuildMap's stage records (COLMAP skipped, the model
// still read and checked). TempleMapTest checks it; ExtendTempleMapTest extends copies of it.
// Tests that map with other options (tracker/'s TempleRingTest) keep theirs in another folder
// beside it, built once the same way: ctest runs every test in a process of its own, and the
// three templeRing tracker tests built the same map three times (40 s each).

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "mapping/colmap_pipeline.h"
#include "recordings/importers.h"
#include "recordings/recording.h"

namespace arview::testing {

inline std::filesystem::path TempleMapRoot() {
  return std::filesystem::temp_directory_path() / ("arview_temple_map_test_" + std::to_string(::getuid()));
}

// The map in TempleMapRoot()/<map_folder> made with `options` of the recording imported from
// `source` (templeRing) into TempleMapRoot()/recording, which `recording` receives. Each folder
// holds one set of options: a test that maps with other options names another folder. Throws
// what BuildMap throws.
inline mapping::MapBuildResult BuildSharedTempleMap(const std::filesystem::path& source, recordings::Recording* recording,
                                                    const std::string& map_folder, const mapping::MapBuildOptions& options,
                                                    const mapping::MapBuildCallbacks& cb = {}) {
  const std::filesystem::path root = TempleMapRoot();
  std::filesystem::create_directories(root);
  const int lock = ::open((root / "lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock < 0) throw map::MapError((root / "lock").string() + ": cannot open");
  ::flock(lock, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }  // closing releases the lock
  } unlock{lock};
  if (!std::filesystem::exists(root / "recording" / "frames.txt")) {
    recordings::ImportOptions io;
    io.overwrite = true;
    recordings::ImportMiddlebury(source, root / "recording", io);
  }
  *recording = recordings::LoadRecording(root / "recording");
  return mapping::BuildMap(*recording, root / map_folder, options, cb);
}

// The suite's default: templeRing's even frames, arview's matching on small frames (kAuto would
// take COLMAP's: the suite covers it whole), in TempleMapRoot()/map.
inline mapping::MapBuildResult BuildSharedTempleMap(const std::filesystem::path& source, recordings::Recording* recording,
                                                    const mapping::MapBuildCallbacks& cb = {}) {
  mapping::MapBuildOptions options;
  options.frames_spec = "0-46:2";
  options.match_engine = mapping::MatchEngine::kArview;
  return BuildSharedTempleMap(source, recording, "map", options, cb);
}

}  // namespace arview::testing
