#pragma once
// templeRing's 24 even frames mapped with COLMAP once for every test process of a user: the map
// lives in $TMPDIR/arview_temple_map_test_<uid>/map under a file lock; the first process builds
// it, every other one re-uses it through BuildMap's stage records (COLMAP skipped, the model
// still read and checked). TempleMapTest checks it; ExtendTempleMapTest extends copies of it.

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

// The map in TempleMapRoot()/map of the recording imported from `source` (templeRing) into
// TempleMapRoot()/recording, which `recording` receives. Throws what BuildMap throws.
inline mapping::MapBuildResult BuildSharedTempleMap(const std::filesystem::path& source, recordings::Recording* recording,
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
  mapping::MapBuildOptions options;
  options.frames_spec = "0-46:2";
  // arview's matching on small frames (kAuto would take COLMAP's): the suite covers it whole.
  options.match_engine = mapping::MatchEngine::kArview;
  return mapping::BuildMap(*recording, root / "map", options, cb);
}

}  // namespace arview::testing
