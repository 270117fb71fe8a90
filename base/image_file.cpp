#include "base/image_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/input_guard.h"

namespace arview {

namespace {

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
// The IEND chunk: length 0, type, CRC; it ends every complete PNG.
constexpr std::string_view kPngEnd("\0\0\0\0IEND\xae\x42\x60\x82", 12);

std::uint32_t BigEndian32(std::string_view bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
}

void RequireDecodableSize(const std::string& file, long long width, long long height) {
  if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImagePixels) {
    throw Error(file + ": the image header says " + std::to_string(width) + "x" + std::to_string(height) +
                " pixels (at most " + std::to_string(kMaxImageSide) + " a side and " + std::to_string(kMaxImagePixels) +
                " in all)");
  }
}

// The structure libpng would otherwise complain about on stderr before OpenCV gives up.
void CheckPngStructure(const std::string& file, std::string_view bytes) {
  // Signature (8), IHDR length (4) and type (4), width (4), height (4), the rest of IHDR (5), CRC (4).
  if (bytes.size() < 33 || bytes.substr(12, 4) != "IHDR" || BigEndian32(bytes, 8) != 13) {
    throw Error(file + ": not a valid PNG (its IHDR header is missing or damaged)");
  }
  RequireDecodableSize(file, BigEndian32(bytes, 16), BigEndian32(bytes, 20));
  if (bytes.size() < kPngSignature.size() + 25 + kPngEnd.size() || bytes.substr(bytes.size() - kPngEnd.size()) != kPngEnd) {
    throw Error(file + ": the PNG is cut short (it does not end with an IEND chunk; truncated or still being written?)");
  }
}

}  // namespace

cv::Mat ReadImageFile(const std::filesystem::path& file, int imread_flags) {
  const std::string name = file.string();
  std::string bytes = ReadFileUpTo(file, kMaxImageFileBytes);  // regular files only (InputError)
  if (bytes.empty()) throw Error(name + ": the image file is empty");
  const std::string_view view(bytes);
  if (view.substr(0, kPngSignature.size()) == kPngSignature) CheckPngStructure(name, view);
  cv::Mat image;
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1, bytes.data());
    image = cv::imdecode(encoded, imread_flags);
  } catch (const cv::Exception& e) {
    throw Error(name + ": cannot be decoded as an image (" + e.err + ")");
  }
  if (image.empty()) throw Error(name + ": cannot be read as an image");
  return image;
}

void WriteImageAtomically(const std::filesystem::path& file, const cv::Mat& image, const std::vector<int>& params) {
  if (image.empty()) throw Error(file.string() + ": cannot write an empty image");
  const std::string extension = file.extension().string();
  if (extension.empty()) throw Error(file.string() + ": no extension to choose the image format by");
  std::vector<unsigned char> encoded;
  bool ok = false;
  try {
    ok = cv::imencode(extension, image, encoded, params);
  } catch (const cv::Exception& e) {
    throw Error(file.string() + ": cannot encode the image (" + e.msg + ")");
  }
  if (!ok) throw Error(file.string() + ": cannot encode the image as " + extension);
  WriteFileAtomically(file, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
}

}  // namespace arview
