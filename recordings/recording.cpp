#include "recordings/recording.h"

#include "base/image_file.h"
#include "base/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "base/input_guard.h"
#include "base/library_errors.h"

namespace arview::recordings {

namespace fs = std::filesystem;

bool Recording::IsVideo() const {
  if (frames.size() < 2) {
    if (frames.empty()) return false;
    const std::string ext = fs::path(frames[0].path).extension().string();
    return ext == ".mp4" || ext == ".avi" || ext == ".mkv" || ext == ".mov" || ext == ".webm";
  }
  return frames[0].path == frames[1].path;
}

cv::Mat Recording::ReadImage(size_t index) const {
  const fs::path p = FramePath(index);
  try {
    return ReadImageFile(p, cv::IMREAD_COLOR);
  } catch (const Error& e) {
    throw RecordingError(e.what());
  }
}

namespace {

std::vector<FrameEntry> ReadFrameListFile(const fs::path& file) {
  // A FIFO or a device (a link to /dev/zero) would never end: only a regular file of sane size.
  std::istringstream in;
  try {
    in.str(ReadFileUpTo(file, kMaxTextFileBytes));
  } catch (const InputError& e) {
    throw RecordingError(e.what());
  }
  std::vector<FrameEntry> frames;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    FrameEntry e;
    if (!(ss >> e.timestamp) || !std::isfinite(e.timestamp)) {
      throw RecordingError(file.string() + ":" + std::to_string(line_no) + ": expected 'timestamp path'");
    }
    std::getline(ss >> std::ws, e.path);
    if (e.path.empty()) {
      throw RecordingError(file.string() + ":" + std::to_string(line_no) + ": frame path missing");
    }
    // A NUL byte cut every message that quoted the path ("arview: rec/frames/"), and no file name
    // holds one; other control characters have no place in a frame's name either.
    const auto control = std::find_if(e.path.begin(), e.path.end(), [](char c) {
      return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
    });
    if (control != e.path.end()) {
      throw RecordingError(file.string() + ":" + std::to_string(line_no) + ": the frame path '" +
                           PrintableForMessage(e.path) + "' holds the control character " +
                           PrintableForMessage(std::string(1, *control)) + " (a frame path is printable text)");
    }
    if (!frames.empty() && e.timestamp <= frames.back().timestamp) {
      throw RecordingError(file.string() + ":" + std::to_string(line_no) +
                           ": timestamps must increase strictly");
    }
    frames.push_back(std::move(e));
  }
  if (frames.empty()) throw RecordingError(file.string() + ": lists no frames");
  return frames;
}

}  // namespace

std::vector<FrameEntry> ReadFrameList(const fs::path& file) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<RecordingError>(file.string(), [&] { return ReadFrameListFile(file); });
}

namespace {

Recording LoadRecordingFolder(const fs::path& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw RecordingError(root.string() + ": recording folder does not exist");
  Recording r;
  r.root = root;
  const fs::path camera_file = root / "camera.yaml";
  if (!fs::exists(camera_file, ec)) throw RecordingError(camera_file.string() + ": missing (every recording needs camera.yaml)");
  try {
    r.camera = calib::LoadCamera(camera_file);
  } catch (const calib::CameraError& e) {
    throw RecordingError(e.what());
  }
  if (!fs::exists(root / "frames.txt", ec)) {
    throw RecordingError((root / "frames.txt").string() + ": missing (every recording needs frames.txt)");
  }
  r.frames = ReadFrameList(root / "frames.txt");
  std::set<std::string> checked;
  for (const FrameEntry& f : r.frames) {
    if (!checked.insert(f.path).second) continue;
    // A frame path such as ../../../../etc/passwd (or a symlink out of the folder) is refused:
    // a recording holds its own frames, and COLMAP would be handed whatever it names.
    try {
      ResolveInside(root, f.path, (root / "frames.txt").string());
    } catch (const InputError& e) {
      throw RecordingError(e.what());
    }
    if (!fs::is_regular_file(root / f.path, ec)) {
      throw RecordingError((root / f.path).string() + ": listed in frames.txt but missing");
    }
  }
  if (checked.size() != 1 && checked.size() != r.frames.size()) {
    throw RecordingError((root / "frames.txt").string() +
                         ": lists some files more than once (expected one file per frame, or one video)");
  }
  const fs::path gt = root / "groundtruth.txt";
  if (fs::exists(gt, ec)) r.groundtruth = ReadTum(gt);
  return r;
}

}  // namespace

Recording LoadRecording(const fs::path& root) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<RecordingError>(root.string(), [&] { return LoadRecordingFolder(root); });
}

void PrepareRecordingFolder(const fs::path& out_dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(out_dir, ec)) {
    if (!fs::is_directory(out_dir, ec)) throw RecordingError(out_dir.string() + ": exists and is not a folder");
    if (!fs::is_empty(out_dir, ec)) {
      if (!fs::exists(out_dir / "frames.txt", ec)) {
        throw RecordingError(out_dir.string() + ": exists, is not empty and is not a recording; choose another --out");
      }
      if (!overwrite) {
        throw RecordingError(out_dir.string() + ": already holds a recording (use --force to replace it)");
      }
      fs::remove(out_dir / "frames.txt", ec);
      for (const char* name : {"camera.yaml", "groundtruth.txt"}) fs::remove(out_dir / name, ec);
      fs::remove_all(out_dir / "frames", ec);
      if (ec) throw RecordingError(out_dir.string() + ": cannot clear the old recording (" + ec.message() + ")");
    }
  }
  fs::create_directories(out_dir / "frames", ec);
  if (ec) throw RecordingError(out_dir.string() + ": cannot create the recording folder (" + ec.message() + ")");
}

void WriteFramesTxt(const fs::path& root, const std::vector<FrameEntry>& frames) {
  const fs::path file = root / "frames.txt";
  WriteFileAtomically(file, [&](std::ostream& out) {
    out << "# timestamp path\n";
    char buf[64];
    for (const FrameEntry& f : frames) {
      std::snprintf(buf, sizeof(buf), "%.9f", f.timestamp);
      out << buf << ' ' << f.path << '\n';
    }
  });
}

namespace {

int ParseIndex(const std::string& text, const std::string& spec) {
  if (text.empty() || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    throw RecordingError("frame spec '" + spec + "': '" + text + "' is not a frame index");
  }
  if (text.size() > 9) throw RecordingError("frame spec '" + spec + "': index '" + text + "' is too large");
  return std::stoi(text);
}

}  // namespace

std::vector<int> ParseFrameSpec(const std::string& spec, int frame_count) {
  std::set<int> out;
  std::stringstream ss(spec);
  std::string item;
  bool any = false;
  // getline reads no item after a trailing comma: "1," would have been taken for "1".
  const size_t last = spec.find_last_not_of(" \t");
  if (last != std::string::npos && spec[last] == ',') throw RecordingError("frame spec '" + spec + "': empty item");
  while (std::getline(ss, item, ',')) {
    // Spaces and tabs around an item only: removing every space joined "00 02 2" into frame 22
    // (found by fuzz_flags's grammar check); a space inside an item is now not a frame index.
    const size_t first = item.find_first_not_of(" \t");
    if (first == std::string::npos) throw RecordingError("frame spec '" + spec + "': empty item");
    item = item.substr(first, item.find_last_not_of(" \t") + 1 - first);
    any = true;
    int step = 1;
    std::string range = item;
    if (const auto colon = item.find(':'); colon != std::string::npos) {
      step = ParseIndex(item.substr(colon + 1), spec);
      if (step <= 0) throw RecordingError("frame spec '" + spec + "': step must be positive");
      range = item.substr(0, colon);
    }
    int a = 0, b = 0;
    if (const auto dash = range.find('-'); dash != std::string::npos) {
      a = ParseIndex(range.substr(0, dash), spec);
      b = ParseIndex(range.substr(dash + 1), spec);
      if (b < a) throw RecordingError("frame spec '" + spec + "': range " + range + " runs backwards");
    } else {
      // "0:1" too (found by fuzz_flags's grammar check): a step is given with a range only.
      if (item.find(':') != std::string::npos)
        throw RecordingError("frame spec '" + spec + "': a step needs a range (a-b:step)");
      a = b = ParseIndex(range, spec);
    }
    if (b >= frame_count) {
      throw RecordingError("frame spec '" + spec + "': frame " + std::to_string(b) +
                           " is beyond the recording's " + std::to_string(frame_count) + " frames (0-based)");
    }
    for (int i = a; i <= b; i += step) out.insert(i);
  }
  if (!any) throw RecordingError("frame spec is empty");
  return {out.begin(), out.end()};
}

}  // namespace arview::recordings
