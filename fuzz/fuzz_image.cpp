// Frames through arview::ReadImageFile (base/image_file.h): the PNG chunk walk and the JPEG
// structure check, then our own decoders (base/png_decoder.h on libpng, base/jpeg_decoder.h on
// libjpeg-turbo; Debian's builds, not instrumented). The seeds are small PNGs and JPEGs written
// by OpenCV's encoders.
//
// A PNG's CRCs make nearly every mutation a refusal by the chunk walk, before libpng; so each
// PNG input is also decoded with its CRCs recomputed, as a writer that computed them over damaged
// data would leave it: what reaches DecodePng is then the mutated header, palette and data, as
// for issue 17's "libpng still prints its line" case. What decodes is decoded again with
// IMREAD_UNCHANGED and IMREAD_GRAYSCALE (16-bit samples, alpha, RGB to gray: other libpng paths).
#include <zlib.h>

#include <cstdint>
#include <exception>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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
  // PNGs of other kinds: gray, and 16-bit with alpha.
  cv::Mat grey, deep;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(image, deep, cv::COLOR_BGR2BGRA);
  deep.convertTo(deep, CV_16U, 257.0);
  for (const auto& [name, kind] : {std::pair{"grey.png", grey}, std::pair{"deep.png", deep}}) {
    std::vector<unsigned char> encoded;
    cv::imencode(".png", kind, encoded);
    arview::fuzz::WriteBytes(seeds / name, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  }
  // A progressive JPEG: several scans, each with its own Huffman tables.
  std::vector<unsigned char> encoded;
  cv::imencode(".jpg", image, encoded, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  arview::fuzz::WriteBytes(seeds / "progressive.jpg",
                           std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  return 0;
}

namespace {

// The PNG with every chunk's CRC (those that fit in the input) computed over its type and data.
std::string WithCrcsRecomputed(std::string png) {
  const auto u32 = [&](size_t at) {
    const auto* b = reinterpret_cast<const unsigned char*>(png.data() + at);
    return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
  };
  for (size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = u32(at);
    if (length > png.size() - at - 12) break;
    const auto crc = static_cast<std::uint32_t>(
        crc32(0, reinterpret_cast<const Bytef*>(png.data() + at + 4), static_cast<uInt>(4 + length)));
    for (int i = 0; i < 4; ++i) png[at + 8 + length + i] = static_cast<char>(crc >> (24 - 8 * i));
    at += 12 + length;
  }
  return png;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("frame", data, size);
  try {
    (void)arview::ReadImageFile(file, cv::IMREAD_COLOR);
  } catch (const std::exception&) {
  }
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.substr(0, 8) != std::string_view("\x89PNG\r\n\x1a\n", 8)) return 0;
  const std::string fixed = WithCrcsRecomputed(std::string(bytes));
  for (int flags : {cv::IMREAD_COLOR, cv::IMREAD_UNCHANGED, cv::IMREAD_GRAYSCALE}) {
    try {
      (void)arview::DecodeImageBytes(fixed, "frame (CRCs recomputed)", flags);
    } catch (const std::exception&) {
      break;
    }
  }
  return 0;
}
