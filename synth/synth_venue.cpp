#include "synth/synth_venue.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <sstream>
#include <vector>

#include "base/atomic_file.h"
#include "base/image_file.h"
#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "synth/recording_folder.h"

namespace arview::synth {
namespace {

namespace fs = std::filesystem;

void ValidateVenueOptions(const SynthVenueOptions& o) {
  auto fail = [](const std::string& what) { throw render::RenderError("synth venue: " + what); };
  if (o.out.empty()) fail("an output folder is required");
  if (o.layout.rooms < 2 || o.layout.rooms > kMaxVenueRooms)
    fail("--rooms must be in 2.." + std::to_string(kMaxVenueRooms) + ", got " + std::to_string(o.layout.rooms));
  if (o.frames < 2 || o.frames > 1000000) fail("--frames must be in 2..1000000, got " + std::to_string(o.frames));
  if (!(o.fps > 0 && o.fps <= 1000)) fail("frame rate must be in (0, 1000]");
  if (o.width < 64 || o.height < 48 || o.width > 7680 || o.height > 4320)
    fail("--size must be between 64x48 and 7680x4320, got " + std::to_string(o.width) + "x" + std::to_string(o.height));
}

std::vector<int> VenueFrames(const SynthVenueOptions& o) {
  if (o.frames_subset.empty()) {
    std::vector<int> every(o.frames);
    for (int i = 0; i < o.frames; ++i) every[i] = i;
    return every;
  }
  try {
    return recordings::ParseFrameSpec(o.frames_subset, o.frames);
  } catch (const Error& e) {
    throw render::RenderError(std::string("synth venue: --subset: ") + e.what());
  }
}


}  // namespace

int SynthesizeVenue(const SynthVenueOptions& o, const std::function<void(int, int)>& progress) {
  ValidateVenueOptions(o);
  const std::vector<int> indices = VenueFrames(o);
  const RoomScene scene = MakeVenueScene(o.layout, o.seed);
  const calib::Camera camera = RoomCamera(o.width, o.height);
  std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create(o.gl);
  PrepareRecordingFolder(o.out, o.overwrite, {"frames.txt", "groundtruth.txt", "camera.yaml", "rooms.txt"});
  RoomRenderer renderer(*context, scene, camera, o.samples);
  const VenueWalk walk(o.layout, o.frames / o.fps);

  std::vector<recordings::FrameEntry> entries;
  recordings::Trajectory groundtruth;
  std::ostringstream rooms;
  rooms << "# arview synth venue: the room each frame's camera is in\n# timestamp room\n";
  for (size_t n = 0; n < indices.size(); ++n) {
    const double t = indices[n] / o.fps;
    const calib::Pose pose = walk.At(t);
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", indices[n]);
    WriteImageAtomically(o.out / name, renderer.Render(pose), {cv::IMWRITE_PNG_COMPRESSION, 1});
    entries.push_back({t, name});
    groundtruth.push_back({t, pose});
    char line[64];
    std::snprintf(line, sizeof line, "%.6f %s\n", t, VenueLayout::RoomName(o.layout.RoomAt(pose.Center())).c_str());
    rooms << line;
    if (progress) progress(static_cast<int>(n) + 1, static_cast<int>(indices.size()));
  }
  calib::SaveCamera(camera, o.out / "camera.yaml");
  recordings::WriteFramesTxt(o.out, entries);
  WriteFileAtomically(o.out / "rooms.txt", rooms.str());
  recordings::WriteTum(groundtruth, o.out / "groundtruth.txt",
                       "arview synth venue, " + std::to_string(o.layout.rooms) + " rooms, seed " + std::to_string(o.seed) +
                           ", world: metres, z up, floor z = 0");
  return static_cast<int>(indices.size());
}

}  // namespace arview::synth
