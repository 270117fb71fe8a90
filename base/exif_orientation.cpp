#include "base/exif_orientation.h"

#include <opencv2/core.hpp>

#include <algorithm>

namespace arview {

unsigned TiffOrientation(const unsigned char* tiff, std::size_t size) {
  const bool little = size >= 2 && tiff[0] == 'I' && tiff[1] == 'I';
  const auto u16 = [&](std::size_t at) -> long long {
    if (at + 1 >= size) return -1;
    return little ? tiff[at] | (tiff[at + 1] << 8) : (tiff[at] << 8) | tiff[at + 1];
  };
  const auto u32 = [&](std::size_t at) -> long long {
    if (at + 3 >= size) return -1;
    return little ? (u16(at) | (u16(at + 2) << 16)) : ((u16(at) << 16) | u16(at + 2));
  };
  if (u16(2) != 42) return 0;
  const long long ifd = u32(4);
  const long long entries = ifd < 0 ? -1 : u16(static_cast<std::size_t>(ifd));
  for (long long i = 0; i < entries; ++i) {
    const std::size_t entry = static_cast<std::size_t>(ifd) + 2 + 12 * static_cast<std::size_t>(i);
    const long long tag = u16(entry);
    if (tag < 0) return 0;
    if (tag == 0x0112) return static_cast<unsigned>(std::max(u16(entry + 8), 0ll));
  }
  return 0;
}

cv::Mat ApplyExifOrientation(const cv::Mat& image, unsigned orientation) {
  if (orientation < 2 || orientation > 8) return image;
  cv::Mat upright = image;
  if (orientation >= 5) cv::transpose(image, upright);
  cv::Mat flipped;
  switch (orientation) {
    case 2: case 6: cv::flip(upright, flipped, 1); return flipped;   // horizontally
    case 3: case 7: cv::flip(upright, flipped, -1); return flipped;  // both ways
    case 4: case 8: cv::flip(upright, flipped, 0); return flipped;   // vertically
    default: return upright;                                         // 5: transposed only
  }
}

}  // namespace arview
