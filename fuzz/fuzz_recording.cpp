// A recording folder through recordings::LoadRecording: the input is frames.txt, then (after a
// line "=====") groundtruth.txt. camera.yaml and three frame files are fixed, so that the
// fuzzer spends its time on the two lists and on the frame paths they name.
#include <exception>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "recordings/recording.h"

namespace {

const std::filesystem::path& RecordingFolder() {
  static const std::filesystem::path root = [] {
    const auto folder = arview::fuzz::ScratchFolder() / "recording";
    std::filesystem::create_directories(folder / "frames");
    const auto camera = arview::calib::Camera::Pinhole(64, 48, 50, 50, 31.5, 23.5);
    arview::calib::SaveCamera(camera, folder / "camera.yaml");
    for (const char* name : {"000000.png", "000001.png", "000002.png"}) {
      arview::fuzz::WriteBytes(folder / "frames" / name, "not decoded by LoadRecording");
    }
    return folder;
  }();
  return root;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& root = RecordingFolder();
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  const std::string_view frames = arview::fuzz::NextPart(rest, "\n=====\n");
  arview::fuzz::WriteBytes(root / "frames.txt", frames);
  std::error_code ec;
  std::filesystem::remove(root / "groundtruth.txt", ec);
  if (!rest.empty()) arview::fuzz::WriteBytes(root / "groundtruth.txt", rest);
  try {
    (void)arview::recordings::LoadRecording(root);
  } catch (const std::exception&) {
  }
  try {
    (void)arview::recordings::ReadFrameList(root / "frames.txt");
  } catch (const std::exception&) {
  }
  return 0;
}
