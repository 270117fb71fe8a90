#pragma once
// The EXIF orientation as OpenCV 4.6 reads and applies it, shared by our JPEG and PNG decoders
// (base/jpeg_decoder.h, base/png_decoder.h), which must give cv::imread's pixels.

#include <cstddef>

namespace cv {
class Mat;
}

namespace arview {

// The orientation in an EXIF TIFF block (from its byte-order mark on: a JPEG's APP1 segment
// after "Exif\0\0", a PNG's eXIf chunk), as OpenCV 4.6's ExifReader reads it: little-endian for
// "II" and big-endian otherwise, 42 after the byte order, then the first IFD's 12-byte entries,
// the first with tag 0x0112 giving the value. 0 when there is none (or the block ends first).
unsigned TiffOrientation(const unsigned char* tiff, std::size_t size);

// OpenCV's ApplyExifOrientation: orientations 2-8 flip and transpose the image to stand upright;
// other values return `image` itself.
cv::Mat ApplyExifOrientation(const cv::Mat& image, unsigned orientation);

}  // namespace arview
