// Frames through arview::ReadImageFile (base/image_file.h): the PNG and JPEG structure checks,
// then OpenCV's decoders (libpng, libjpeg; Debian's builds, not instrumented). The seeds are a
// small PNG and JPEG written by OpenCV's encoders.
#include <exception>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/image_file.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  cv::Mat image(24, 32, CV_8UC3);
  cv::randu(image, 0, 255);
  for (const char* extension : {".png", ".jpg"}) {
    std::vector<unsigned char> encoded;
    cv::imencode(extension, image, encoded);
    arview::fuzz::WriteBytes(seeds / (std::string("small") + extension),
                             std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  }
  // A progressive JPEG: several scans, each with its own Huffman tables.
  std::vector<unsigned char> encoded;
  cv::imencode(".jpg", image, encoded, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  arview::fuzz::WriteBytes(seeds / "progressive.jpg",
                           std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("frame", data, size);
  try {
    (void)arview::ReadImageFile(file, cv::IMREAD_COLOR);
  } catch (const std::exception&) {
  }
  return 0;
}
