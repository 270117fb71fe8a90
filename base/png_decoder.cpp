#include "base/png_decoder.h"

#include <png.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>

#include "base/error.h"
#include "base/image_file.h"
#include "base/exif_orientation.h"

namespace arview {

namespace {

constexpr png_uint_32 ChunkType(const char (&name)[5]) {
  return (png_uint_32(static_cast<unsigned char>(name[0])) << 24) | (png_uint_32(static_cast<unsigned char>(name[1])) << 16) |
         (png_uint_32(static_cast<unsigned char>(name[2])) << 8) | png_uint_32(static_cast<unsigned char>(name[3]));
}

// The chunks whose faults change the pixels: the image data, the palette, the transparency.
bool MakesThePixels(png_uint_32 chunk) {
  return chunk == ChunkType("IDAT") || chunk == ChunkType("PLTE") || chunk == ChunkType("tRNS");
}

// What libpng's error and warning callbacks report back to RunLibpng, through the setjmp there.
// Nothing is ever printed.
struct QuietErrors {
  std::jmp_buf jump;
  bool armed = false;      // the setjmp in RunLibpng has been made
  bool in_rows = false;    // reading the rows: every fault is in the image data
  bool damaged = false;    // the fault is in the data that makes the pixels
  bool cut_short = false;  // the bytes ended before libpng was done
  char message[512] = {};
};

// The PNG in memory, handed to libpng by ReadFromMemory.
struct Source {
  const unsigned char* data;
  size_t size;
  size_t at = 0;
};

QuietErrors& ErrorsOf(png_structp png) { return *static_cast<QuietErrors*>(png_get_error_ptr(png)); }

// libpng's messages about the image data that come while another chunk is current: the stream
// ended before the image ("Not enough image data", after reading the next chunk's header), an
// IDAT after the image's ("Too many IDATs found"), a CRC error (ReadImageFile checks every CRC
// first, so it is not seen there).
constexpr const char* kDamageMessages[] = {"Not enough image data", "Too many IDATs found", "Too much image data",
                                           "Extra compressed data", "CRC error"};

bool MeansDamagedData(png_structp png, png_const_charp message) {
  if (ErrorsOf(png).in_rows || MakesThePixels(png_get_io_chunk_type(png))) return true;
  for (const char* damage : kDamageMessages) {
    if (message != nullptr && std::strstr(message, damage) != nullptr) return true;
  }
  return false;
}

[[noreturn]] void JumpWithMessage(png_structp png, png_const_charp message) {
  QuietErrors& errors = ErrorsOf(png);
  // An error while png_create_read_struct sets up (out of memory): back to its own setjmp,
  // which makes it return null.
  if (!errors.armed) png_longjmp(png, 1);
  std::snprintf(errors.message, sizeof errors.message, "%s", message != nullptr ? message : "unknown error");
  errors.damaged = MeansDamagedData(png, message);
  std::longjmp(errors.jump, 1);
}

void ErrorFunction(png_structp png, png_const_charp message) { JumpWithMessage(png, message); }

// libpng's warnings (and the "benign errors" it turns into warnings when reading) on the image
// data, the palette and the transparency mean the pixels are not what was written: "IDAT:
// incorrect data check" (the stream's Adler-32), "IDAT: Extra compressed data", "Too much image
// data", "Too many IDATs found", "tRNS: invalid", ...
// They jump out as errors. The others are about metadata (gAMA, cHRM, iCCP, sRGB, pHYs, text,
// eXIf, unknown chunks): the pixels are right, and they are dropped.
void WarningFunction(png_structp png, png_const_charp message) {
  if (MeansDamagedData(png, message)) JumpWithMessage(png, message);
}

void ReadFromMemory(png_structp png, png_bytep out, size_t length) {
  Source& source = *static_cast<Source*>(png_get_io_ptr(png));
  if (length > source.size - source.at) {
    ErrorsOf(png).cut_short = true;
    png_error(png, "the data ends early");
  }
  std::memcpy(out, source.data + source.at, length);
  source.at += length;
}

// The type OpenCV 4.6 makes for this header (PngDecoder::readHeader), then for these flags
// (imread_'s rule): a palette or RGB image with tRNS is 4 channels, gray with tRNS 1.
int ImreadType(png_structp png, png_infop info, int imread_flags) {
  const int colour = png_get_color_type(png, info);
  int channels = 1;
  if (colour == PNG_COLOR_TYPE_RGB || colour == PNG_COLOR_TYPE_PALETTE) {
    png_bytep trans = nullptr;
    int num_trans = 0;
    png_color_16p trans_values = nullptr;
    png_get_tRNS(png, info, &trans, &num_trans, &trans_values);
    channels = num_trans > 0 ? 4 : 3;
  } else if (colour == PNG_COLOR_TYPE_GRAY_ALPHA || colour == PNG_COLOR_TYPE_RGB_ALPHA) {
    channels = 4;
  }
  int depth = png_get_bit_depth(png, info) == 16 ? CV_16U : CV_8U;
  if (imread_flags != cv::IMREAD_UNCHANGED) {
    if ((imread_flags & cv::IMREAD_ANYDEPTH) == 0) depth = CV_8U;
    const bool colour_out = (imread_flags & cv::IMREAD_COLOR) != 0 || ((imread_flags & cv::IMREAD_ANYCOLOR) != 0 && channels > 1);
    channels = colour_out ? 3 : 1;
  }
  return CV_MAKETYPE(depth, channels);
}

// Every libpng call, after the setjmp its errors return to: on an error (or a warning that means
// damage) it returns false with errors.message set. Nothing here owns a resource that the jump
// would skip: `image` is the caller's, libpng's memory is freed by png_destroy_read_struct.
bool RunLibpng(png_structp png, png_infop info, png_infop end_info, QuietErrors& errors, Source& source,
               int imread_flags, cv::Mat& image, unsigned& orientation) {
  if (setjmp(errors.jump) != 0) return false;
  errors.armed = true;
  png_set_read_fn(png, &source, ReadFromMemory);
  png_read_info(png, info);
  image.create(static_cast<int>(png_get_image_height(png, info)), static_cast<int>(png_get_image_width(png, info)),
               ImreadType(png, info, imread_flags));
  const int colour = png_get_color_type(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  // OpenCV 4.6's PngDecoder::readData, call for call: the order matters to libpng.
  if (image.depth() == CV_8U && bit_depth == 16) {
    png_set_strip_16(png);
  } else if constexpr (std::endian::native == std::endian::little) {
    png_set_swap(png);  // 16-bit samples in the machine's order
  }
  if (image.channels() < 4) {
    png_set_strip_alpha(png);
  } else {
    png_set_tRNS_to_alpha(png);
  }
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  const bool colour_out = image.channels() > 1;
  if ((colour & PNG_COLOR_MASK_COLOR) != 0 && colour_out) {
    png_set_bgr(png);
  } else if (colour_out) {
    png_set_gray_to_rgb(png);
  } else {
    png_set_rgb_to_gray(png, PNG_ERROR_ACTION_NONE, 0.299, 0.587);
  }
  const int passes = png_set_interlace_handling(png);  // Adam7: 7 passes over the rows
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != image.cols * image.elemSize()) {
    png_error(png, "the rows libpng makes do not match the image (a bug in arview's PNG decoder)");
  }
  // What png_read_image does, without its array of row pointers.
  errors.in_rows = true;
  for (int pass = 0; pass < passes; ++pass) {
    for (int y = 0; y < image.rows; ++y) png_read_row(png, image.ptr(y), nullptr);
  }
  errors.in_rows = false;
  png_read_end(png, end_info);  // the rest of the stream (its Adler-32) and the chunks after it
  // OpenCV takes the eXIf chunk before the image data, else the one after it.
  png_uint_32 exif_size = 0;
  png_bytep exif = nullptr;
  if (png_get_valid(png, info, PNG_INFO_eXIf) != 0) {
    png_get_eXIf_1(png, info, &exif_size, &exif);
  } else if (png_get_valid(png, end_info, PNG_INFO_eXIf) != 0) {
    png_get_eXIf_1(png, end_info, &exif_size, &exif);
  }
  orientation = exif != nullptr && exif_size > 0 ? TiffOrientation(exif, exif_size) : 0;
  return true;
}

// The flags this decoder reproduces cv::imdecode for (see the header).
bool Reproduced(int imread_flags) {
  constexpr int kKnown = cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR | cv::IMREAD_IGNORE_ORIENTATION;
  return imread_flags == cv::IMREAD_UNCHANGED || (imread_flags >= 0 && (imread_flags & ~kKnown) == 0);
}

}  // namespace

cv::Mat DecodePng(std::string_view bytes, const std::string& name, int imread_flags) {
  // cv::imdecode's fallback below takes an int length.
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) throw Error(name + ": the PNG is too large");
  const int flags = Reproduced(imread_flags) ? imread_flags : cv::IMREAD_UNCHANGED;
  QuietErrors errors{};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &errors, ErrorFunction, WarningFunction);
  if (png == nullptr) throw Error(name + ": cannot decode the PNG (libpng could not be set up)");
  png_infop info = png_create_info_struct(png);
  png_infop end_info = png_create_info_struct(png);
  Source source{reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()};
  cv::Mat image;
  unsigned orientation = 0;
  const bool decoded =
      info != nullptr && end_info != nullptr && RunLibpng(png, info, end_info, errors, source, flags, image, orientation);
  png_destroy_read_struct(&png, &info, &end_info);
  if (!decoded) {
    if (errors.cut_short) {
      throw Error(name + ": the PNG is cut short (its data ends at byte " + std::to_string(bytes.size()) +
                  ", before the end of the image; truncated or still being written?)");
    }
    if (errors.message[0] == '\0') throw Error(name + ": cannot decode the PNG (libpng could not be set up)");
    throw Error(name + (errors.damaged ? ": damaged PNG data (libpng: " : ": cannot be decoded as a PNG (libpng: ") +
                errors.message + ")");
  }
  if (flags == imread_flags) {
    const bool orient = imread_flags != cv::IMREAD_UNCHANGED && (imread_flags & cv::IMREAD_IGNORE_ORIENTATION) == 0;
    return orient ? ApplyExifOrientation(image, orientation) : image;
  }
  // Decoded once without a word; what OpenCV does with these flags is its own.
  return ImdecodeOrThrow(bytes, name, imread_flags);
}

}  // namespace arview
