#pragma once
// PNG decoding with libpng directly, so that libpng's errors and warnings become our errors
// instead of lines on stderr. OpenCV's decoder leaves libpng's default handlers in place: a PNG
// whose chunks and CRCs are intact but whose compressed data is not (a writer that computed the
// CRCs over damaged data, an IDAT cut short with its CRC recomputed) printed "libpng error:
// IDAT: invalid distance too far back", "libpng warning: IDAT: incorrect data check", ... and
// was decoded, or not, according to which. ReadImageFile (base/image_file.h) checks the chunks
// and CRCs first, then decodes with this.

#include <string>
#include <string_view>

namespace cv {
class Mat;
}

namespace arview {

// Decodes `bytes` (a PNG) as cv::imdecode(bytes, imread_flags) does with Debian's OpenCV 4.6
// and the same libpng 1.6: the same libpng transformations in the same order, so the same
// pixels and type, for IMREAD_UNCHANGED and every combination of IMREAD_COLOR, IMREAD_ANYDEPTH,
// IMREAD_ANYCOLOR and IMREAD_IGNORE_ORIENTATION (IMREAD_GRAYSCALE is 0), with the orientation of
// an eXIf chunk applied as OpenCV applies it. Other flags (the IMREAD_REDUCED_* ones) are
// decoded once here, to find damage, then by cv::imdecode. Nothing is printed.
//
// Throws arview::Error naming `name`:
//   "<name>: damaged PNG data (libpng: <its message>)" for every fault in the image data (the
//     compressed stream, the rows' filters, too little or too much data) and in the chunks that make the pixels (PLTE, tRNS), whether libpng makes it
//     an error or only a warning;
//   "<name>: the PNG is cut short (...)" when the bytes end before IEND has been read;
//   "<name>: cannot be decoded as a PNG (libpng: <its error>)" for the other errors.
// libpng's warnings about the other ancillary chunks (gAMA, iCCP, pHYs, text, eXIf, ...) are
// metadata: they are dropped, silently, and the image decoded, as OpenCV decodes it.
cv::Mat DecodePng(std::string_view bytes, const std::string& name, int imread_flags);

}  // namespace arview
