#include "base/image_file.h"

#include "base/library_errors.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/input_guard.h"
#include "base/jpeg_decoder.h"
#include "base/png_decoder.h"

namespace arview {

namespace {

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
// The IEND chunk: length 0, type, CRC; it ends every complete PNG.
constexpr std::string_view kPngEnd("\0\0\0\0IEND\xae\x42\x60\x82", 12);
// SOI, and the 0xFF that starts the marker after it: every JPEG begins so.
constexpr std::string_view kJpegStart("\xff\xd8\xff", 3);

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

// Every chunk from IHDR to IEND: its length inside the file, its type four ASCII letters, its
// CRC (over type and data) right, IHDR's fields valid, a PLTE before the data of a palette image,
// some IDAT. The CRC is what catches damage inside the compressed data, which libpng reports
// on stderr ("IDAT: incorrect data check", "bad adaptive filter value", "IDAT: CRC error") with
// OpenCV's decoder: any change of up to 32 bits in a row, and all but 1 in 2^32 of larger
// ones. Not caught here: a writer that computed the CRC over wrong data, or a chunk cut short
// with its CRC recomputed; DecodePng (base/png_decoder.h) finds those as it decodes.
void CheckPngChunks(const std::string& file, std::string_view bytes) {
  const auto damaged = [&](size_t at, const std::string& what) {
    return Error(file + ": not a valid PNG (" + what + " at byte " + std::to_string(at) + ")");
  };
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  // IHDR: width, height, bit depth, colour type, compression, filter, interlace.
  const unsigned depth = b[24], colour = b[25];
  const bool depth_ok = colour == 0   ? (depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)
                        : colour == 3 ? (depth == 1 || depth == 2 || depth == 4 || depth == 8)
                        : (colour == 2 || colour == 4 || colour == 6) && (depth == 8 || depth == 16);
  if (!depth_ok || b[26] != 0 || b[27] != 0 || b[28] > 1) throw damaged(8, "an IHDR header with invalid fields");
  bool palette = false, data = false;
  for (size_t at = kPngSignature.size();;) {
    if (at + 12 > bytes.size()) throw damaged(at, "a chunk cut short");
    const std::uint32_t length = BigEndian32(bytes, at);
    if (length > 0x7fffffffu || at + 12 + length > bytes.size()) throw damaged(at, "a chunk longer than the file");
    const std::string_view type = bytes.substr(at + 4, 4);
    for (char c : type) {
      if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'))) throw damaged(at, "a chunk type that is not four letters");
    }
    const auto crc = static_cast<std::uint32_t>(crc32(0, b + at + 4, 4 + length));
    if (crc != BigEndian32(bytes, at + 8 + length)) {
      throw damaged(at, "the CRC of its " + std::string(type) + " chunk does not match its data");
    }
    if (type == "PLTE") palette = true;
    if (type == "IDAT") {
      if (colour == 3 && !palette) throw damaged(at, "image data before the palette (PLTE)");
      data = true;
    }
    if (type == "IEND") {
      // The caller has checked that IEND ends the file.
      if (!data) throw damaged(at, "no image data (IDAT)");
      return;
    }
    at += 12 + length;
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
  CheckPngChunks(file, bytes);
}

std::uint32_t BigEndian16(std::string_view bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return (std::uint32_t{b[0]} << 8) | b[1];
}

// Frame headers (SOF0-SOF15 but DHT C4, JPG C8 and DAC CC, which share the range).
bool IsStartOfFrame(unsigned char marker) {
  return marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
}

// The structure libjpeg would otherwise warn about on stderr ("Premature end of JPEG file",
// "Corrupt JPEG data: premature end of data segment", "... extraneous bytes before marker")
// while OpenCV goes on decoding: the marker segments from SOI, each length inside the file, the
// frame header (SOF) with its size, every scan (SOS) followed by its entropy-coded data (0xFF00
// stuffing and RST markers inside it) up to the next marker, until EOI. Bytes after EOI are
// accepted (cameras append data there). What is not checked: the entropy-coded data itself (a
// bad Huffman code in a complete file still makes libjpeg warn).
void CheckJpegStructure(const std::string& file, std::string_view bytes) {
  const auto byte = [&](size_t at) { return static_cast<unsigned char>(bytes[at]); };
  const auto cut_short = [&]() {
    return Error(file + ": the JPEG is cut short (it ends before its EOI marker; truncated or still being written?)");
  };
  const auto damaged = [&](size_t at, const std::string& what) {
    return Error(file + ": not a valid JPEG (" + what + " at byte " + std::to_string(at) + ")");
  };
  bool frame = false, scan = false, sequential = false;
  size_t at = 2;  // after SOI
  for (;;) {
    if (at >= bytes.size()) throw cut_short();
    if (byte(at) != 0xff) throw damaged(at, "no marker where one must start");
    while (at < bytes.size() && byte(at) == 0xff) ++at;  // fill bytes before a marker
    if (at >= bytes.size()) throw cut_short();
    const unsigned char marker = byte(at);
    const size_t marker_at = at - 1;
    ++at;
    if (marker == 0xd9) {  // EOI
      if (!frame || !scan) throw damaged(marker_at, "the EOI marker comes before any frame header and scan");
      return;
    }
    if ((marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) continue;  // RSTn, TEM: no length
    if (marker == 0x00 || marker == 0xd8) throw damaged(marker_at, "an unexpected marker");
    if (at + 2 > bytes.size()) throw cut_short();
    const size_t length = BigEndian16(bytes, at);
    if (length < 2) throw damaged(marker_at, "a segment length below 2");
    if (at + length > bytes.size()) throw cut_short();
    if (IsStartOfFrame(marker)) {
      // Precision, height, width, component count, then 3 bytes per component.
      if (frame) throw damaged(marker_at, "a second frame header");
      if (length < 8 || byte(at + 7) == 0 || length != 8u + 3u * byte(at + 7)) {
        throw damaged(marker_at, "a frame header whose length does not match its components");
      }
      RequireDecodableSize(file, BigEndian16(bytes, at + 5), BigEndian16(bytes, at + 3));
      frame = true;
      sequential = marker == 0xc0 || marker == 0xc1;  // baseline, extended sequential (Huffman)
    } else if (marker == 0xda) {  // SOS: its header, then entropy-coded data up to the next marker
      if (!frame) throw damaged(marker_at, "a scan before the frame header");
      if (length < 3 || byte(at + 2) == 0 || length != 6u + 2u * byte(at + 2)) {
        throw damaged(marker_at, "a scan header whose length does not match its components");
      }
      // A sequential scan covers the whole spectrum at full precision: Ss 0, Se 63, Ah Al 0
      // (libjpeg warns "Invalid SOS parameters for sequential JPEG" otherwise).
      if (sequential && (byte(at + length - 3) != 0 || byte(at + length - 2) != 63 || byte(at + length - 1) != 0)) {
        throw damaged(marker_at, "a sequential scan header with progressive parameters");
      }
      size_t data = at + length;
      const size_t data_start = data;
      for (;;) {
        while (data < bytes.size() && byte(data) != 0xff) ++data;
        if (data + 1 >= bytes.size()) throw cut_short();
        const unsigned char next = byte(data + 1);
        if (next == 0x00 || (next >= 0xd0 && next <= 0xd7)) {  // a stuffed 0xFF byte, a restart marker
          data += 2;
          continue;
        }
        if (next == 0xff) {  // fill bytes: the marker is after them
          size_t fill = data + 1;
          while (fill < bytes.size() && byte(fill) == 0xff) ++fill;
          if (fill >= bytes.size()) throw cut_short();
          if (byte(fill) == 0x00) {  // not a marker after all: 0xFF 0x00 stuffing after fill
            data = fill + 1;
            continue;
          }
        }
        break;
      }
      if (data == data_start) throw damaged(data, "a scan without data");
      scan = true;
      at = data;
      continue;
    }
    at += length;
  }
}

// The formats besides PNG and JPEG that arview reads (what `import images` takes; BMP for the
// demo's replay frames), by signature. OpenCV decodes them. Anything else is refused before
// cv::imdecode, which would offer the bytes to every codec it was built with: a 132-byte input of
// fuzz_image that OpenCV took for DICOM made GDCM's reader abort the process (an assert).
std::string_view OtherAcceptedFormat(std::string_view bytes) {
  using namespace std::string_view_literals;
  if (bytes.starts_with("BM"sv)) return "BMP";
  if (bytes.starts_with("II*\0"sv) || bytes.starts_with("MM\0*"sv)) return "TIFF";
  if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6') return "PNM";
  return {};
}

}  // namespace

namespace {

cv::Mat ReadImageFileBytes(const std::filesystem::path& file, int imread_flags) {
  const std::string bytes = ReadFileUpTo(file, kMaxImageFileBytes);  // regular files only (InputError)
  return DecodeImageBytes(bytes, file.string(), imread_flags);
}

}  // namespace

cv::Mat ReadImageFile(const std::filesystem::path& file, int imread_flags) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<Error>(file.string(), [&] { return ReadImageFileBytes(file, imread_flags); });
}

cv::Mat DecodeImageBytes(std::string_view bytes, const std::string& name, int imread_flags) {
  if (bytes.empty()) throw Error(name + ": the image is empty (0 bytes)");
  if (bytes.size() > kMaxImageFileBytes) throw Error(name + ": the image is larger than " + std::to_string(kMaxImageFileBytes) + " bytes");
  if (bytes.substr(0, kPngSignature.size()) == kPngSignature) {
    CheckPngStructure(name, bytes);
    return DecodePng(bytes, name, imread_flags);  // libpng's errors and warnings ours, nothing printed
  }
  if (bytes.substr(0, kJpegStart.size()) == kJpegStart) {
    CheckJpegStructure(name, bytes);
    return DecodeJpeg(bytes, name, imread_flags);  // libjpeg's warnings as errors, nothing printed
  }
  if (OtherAcceptedFormat(bytes).empty()) {
    throw Error(name + ": not a PNG, JPEG, BMP, TIFF or PNM image (its first bytes are '" +
                PrintableForMessage(bytes.substr(0, 8)) + "')");
  }
  return ImdecodeOrThrow(bytes, name, imread_flags);
}

cv::Mat ImdecodeOrThrow(std::string_view bytes, const std::string& name, int imread_flags) {
  cv::Mat image;
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data()));
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
