#include "app/session/keyframe_appearance.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "base/image_file.h"

namespace arview::app {

namespace {

// The image in `file` (grey); empty when there is none or it cannot be read.
cv::Mat ReadIfPresent(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return {};
  try {
    return ReadImageFile(file, cv::IMREAD_GRAYSCALE);
  } catch (const Error&) {
    return {};  // a damaged image only makes the reference rest on fewer keyframes
  }
}

// Whether `recording` holds the very frame `keyframe` was made from.
bool RecordingHolds(const recordings::Recording& recording, const map::Keyframe& keyframe) {
  if (keyframe.frame_index < 0 || static_cast<std::size_t>(keyframe.frame_index) >= recording.frames.size()) return false;
  const recordings::FrameEntry& frame = recording.frames[static_cast<std::size_t>(keyframe.frame_index)];
  return frame.path == keyframe.name && std::abs(frame.timestamp - keyframe.timestamp) < 1e-6;
}

// The keyframe's image from the map folder, or from the recording it was made from; empty when
// neither holds it.
cv::Mat FindKeyframeImage(const map::Keyframe& keyframe, const std::filesystem::path& map_dir,
                          const recordings::Recording* recording) {
  for (const std::filesystem::path& place : {map_dir / "images", map_dir}) {
    if (cv::Mat image = ReadIfPresent(place / keyframe.name); !image.empty()) return image;
  }
  if (recording != nullptr && !recording->IsVideo() && RecordingHolds(*recording, keyframe)) {
    return ReadIfPresent(recording->root / keyframe.name);
  }
  return {};
}

}  // namespace

std::filesystem::path MapFolder(const std::string& map_name) {
  std::error_code ec;
  const std::filesystem::path named(map_name);
  return std::filesystem::is_regular_file(named, ec) ? named.parent_path() : named;
}

tracker::AppearanceReference KeyframeAppearance(const map::Map& map, const std::filesystem::path& map_dir,
                                                const recordings::Recording* recording, int max_images) {
  const std::size_t count = map.keyframes.size();
  const std::size_t wanted = std::min<std::size_t>(count, static_cast<std::size_t>(std::max(0, max_images)));
  std::vector<cv::Mat> images;
  for (std::size_t i = 0; i < wanted; ++i) {
    const map::Keyframe& keyframe = map.keyframes[i * count / wanted];  // spread over the map
    if (cv::Mat image = FindKeyframeImage(keyframe, map_dir, recording); !image.empty()) images.push_back(std::move(image));
  }
  return tracker::ReferenceFromImages(images);
}

}  // namespace arview::app
