#include "synth/recording_folder.h"

namespace arview::synth {

void PrepareRecordingFolder(const std::filesystem::path& out, bool overwrite, std::initializer_list<const char*> files) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) throw render::RenderError(out.string() + ": exists and is not a folder");
  if (fs::exists(out, ec) && !fs::is_empty(out, ec)) {
    if (!overwrite) throw render::RenderError(out.string() + ": folder exists and is not empty (--force replaces the recording)");
    fs::remove_all(out / "frames", ec);
    for (const char* file : files) fs::remove(out / file, ec);
  }
  fs::create_directories(out / "frames", ec);
  if (ec) throw render::RenderError(out.string() + ": cannot create the recording folder (" + ec.message() + ")");
}

void SetPanelCorners(RoomPanel& panel, const Eigen::Vector3d& centre, const Eigen::Vector3d& right, const Eigen::Vector3d& up,
                     double width, double height) {
  panel.corners[0] = centre - right * width / 2 + up * height / 2;
  panel.corners[1] = centre + right * width / 2 + up * height / 2;
  panel.corners[2] = centre + right * width / 2 - up * height / 2;
  panel.corners[3] = centre - right * width / 2 - up * height / 2;
}

}  // namespace arview::synth
