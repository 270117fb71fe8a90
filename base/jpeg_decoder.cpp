#include "base/jpeg_decoder.h"

// jpeglib.h needs FILE and size_t declared before it.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
#include <jerror.h>
// clang-format on

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <csetjmp>
#include <limits>

#include "base/error.h"
#include "base/image_file.h"
#include "base/exif_orientation.h"

namespace arview {

namespace {

// libjpeg's error manager, extended: its fatal errors and the warnings that mean damaged data
// jump back to the setjmp in RunLibjpeg with their text; nothing is ever printed. `base` must
// stay the first member: libjpeg hands our callbacks a pointer to it.
struct QuietErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  JpegDamage damage;
  bool damaged;  // a warning jumped (damage), not a fatal error
  char message[JMSG_LENGTH_MAX];
};

QuietErrors& ErrorsOf(j_common_ptr cinfo) { return *reinterpret_cast<QuietErrors*>(cinfo->err); }

// libjpeg's warnings that say the decoded pixels are not what was encoded. The others (an
// unknown JFIF revision, an unknown Adobe colour transform, a damaged ICC profile) are about
// metadata: the pixels are right, and they are let through silently.
bool MeansDamagedData(const jpeg_error_mgr& err, JpegDamage damage) {
  switch (err.msg_code) {
    case JWRN_EXTRANEOUS_DATA:  // bytes where a marker should be; "before marker 0xd9": padding
      return damage == JpegDamage::kRefuse || err.msg_parm.i[1] != JPEG_EOI;
    case JWRN_HIT_MARKER:       // "premature end of data segment"
    case JWRN_HUFF_BAD_CODE:    // "bad Huffman code"
    case JWRN_ARITH_BAD_CODE:
    case JWRN_JPEG_EOF:         // the data ended before EOI
    case JWRN_MUST_RESYNC:      // a restart marker out of place
    case JWRN_NOT_SEQUENTIAL:
    case JWRN_TOO_MUCH_DATA:
    case JWRN_BOGUS_PROGRESSION:
      return true;
    default:
      return false;
  }
}

[[noreturn]] void JumpWithMessage(j_common_ptr cinfo, bool damaged) {
  QuietErrors& errors = ErrorsOf(cinfo);
  errors.base.format_message(cinfo, errors.message);
  errors.damaged = damaged;
  std::longjmp(errors.jump, 1);
}

void ErrorExit(j_common_ptr cinfo) { JumpWithMessage(cinfo, false); }

// Level -1 is a warning; 0 and above are trace messages, ignored.
void EmitMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;
  QuietErrors& errors = ErrorsOf(cinfo);
  ++errors.base.num_warnings;
  if (MeansDamagedData(errors.base, errors.damage)) JumpWithMessage(cinfo, true);
}

void OutputNothing(j_common_ptr) {}

// The orientation in the first APP1 segment, its TIFF header 6 bytes in (past "Exif\0\0", which
// OpenCV 4.6 does not check). 0 when there is none.
unsigned ExifOrientation(const jpeg_decompress_struct& cinfo) {
  const jpeg_marker_struct* app1 = cinfo.marker_list;
  while (app1 != nullptr && app1->marker != JPEG_APP0 + 1) app1 = app1->next;
  constexpr size_t kTiffAt = 6;
  if (app1 == nullptr || app1->data_length <= kTiffAt) return 0;
  return TiffOrientation(app1->data + kTiffAt, app1->data_length - kTiffAt);
}

// What the caller asked for, in libjpeg's terms. `channels` 0: decode only to look for damage
// (flags or a colour space this decoder does not reproduce; cv::imdecode decodes it after).
struct Request {
  int channels;
  J_COLOR_SPACE space;
};

Request RequestFor(const jpeg_decompress_struct& cinfo, int imread_flags) {
  if (cinfo.num_components == 4) return {0, cinfo.out_color_space};  // CMYK, YCCK
  const bool colour = imread_flags == cv::IMREAD_COLOR || (imread_flags == cv::IMREAD_UNCHANGED && cinfo.num_components > 1);
  if (colour) return {3, JCS_EXT_BGR};
  if (imread_flags == cv::IMREAD_GRAYSCALE || imread_flags == cv::IMREAD_UNCHANGED) return {1, JCS_GRAYSCALE};
  return {0, cinfo.out_color_space};
}

// Every libjpeg call, after the setjmp its errors return to: on an error or a damage warning
// it returns false with errors.message set. Nothing here owns a resource that the jump would
// skip: `image` is the caller's, libjpeg's memory is freed by jpeg_destroy_decompress.
bool RunLibjpeg(jpeg_decompress_struct& cinfo, QuietErrors& errors, std::string_view bytes, int imread_flags,
                cv::Mat& image, unsigned& orientation) {
  if (setjmp(errors.jump) != 0) return false;
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, reinterpret_cast<const unsigned char*>(bytes.data()), static_cast<unsigned long>(bytes.size()));
  jpeg_save_markers(&cinfo, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&cinfo, TRUE);
  const Request request = RequestFor(cinfo, imread_flags);
  cinfo.out_color_space = request.space;
  jpeg_start_decompress(&cinfo);
  JSAMPARRAY scratch = nullptr;
  if (request.channels > 0) {
    image.create(static_cast<int>(cinfo.output_height), static_cast<int>(cinfo.output_width), CV_8UC(request.channels));
  } else {
    scratch = cinfo.mem->alloc_sarray(reinterpret_cast<j_common_ptr>(&cinfo), JPOOL_IMAGE,
                                      cinfo.output_width * cinfo.output_components, 1);
  }
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = request.channels > 0 ? image.ptr(static_cast<int>(cinfo.output_scanline)) : scratch[0];
    // From memory libjpeg never suspends; 0 rows would loop forever.
    if (jpeg_read_scanlines(&cinfo, &row, 1) != 1) ERREXIT(&cinfo, JERR_INPUT_EMPTY);
  }
  orientation = ExifOrientation(cinfo);
  jpeg_finish_decompress(&cinfo);  // reads up to EOI: trailing damage is seen here
  return true;
}

}  // namespace

cv::Mat DecodeJpeg(std::string_view bytes, const std::string& name, int imread_flags, JpegDamage damage) {
  // cv::imdecode's fallback below takes an int length.
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) throw Error(name + ": the JPEG is too large");
  QuietErrors errors{};
  errors.damage = damage;
  jpeg_decompress_struct cinfo{};  // zeroed: destroying it is safe even if creating it failed
  cinfo.err = jpeg_std_error(&errors.base);
  errors.base.error_exit = ErrorExit;
  errors.base.emit_message = EmitMessage;
  errors.base.output_message = OutputNothing;
  cv::Mat image;
  unsigned orientation = 0;
  const bool decoded = RunLibjpeg(cinfo, errors, bytes, imread_flags, image, orientation);
  jpeg_destroy_decompress(&cinfo);
  if (!decoded) {
    throw Error(name + (errors.damaged ? ": damaged JPEG data (libjpeg: " : ": cannot be decoded as a JPEG (libjpeg: ") +
                errors.message + ")");
  }
  if (!image.empty()) return imread_flags == cv::IMREAD_UNCHANGED ? image : ApplyExifOrientation(image, orientation);
  // Decoded once without a word; what OpenCV does with these flags or this colour space is its own.
  return ImdecodeOrThrow(bytes, name, imread_flags);
}

}  // namespace arview
