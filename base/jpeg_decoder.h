#pragma once
// JPEG decoding with libjpeg-turbo directly, so that libjpeg's warnings become our errors instead
// of lines on stderr. OpenCV's decoder leaves libjpeg's default message output in place: a JPEG
// whose markers are intact but whose entropy-coded data is damaged (a flipped bit in the scan)
// printed "Corrupt JPEG data: bad Huffman code" and was decoded with the damage visible. JPEG has
// no checksum; decoding is the only way to find such damage.

#include <string>
#include <string_view>

namespace cv {
class Mat;
}

namespace arview {

// What a warning that means damaged data does. Files refuse every one. A live MJPEG stream keeps
// frames whose only fault is bytes between the end of their data and EOI (webcams pad frames
// so, and libjpeg says "Corrupt JPEG data: N extraneous bytes before marker 0xd9"): the image
// is whole.
enum class JpegDamage { kRefuse, kAcceptPaddingBeforeEnd };

// Decodes `bytes` (a JPEG) as cv::imdecode(bytes, imread_flags) does with Debian's OpenCV 4.6
// and the same libjpeg-turbo: the same pixels for IMREAD_COLOR, IMREAD_GRAYSCALE and
// IMREAD_UNCHANGED, with the EXIF orientation applied as OpenCV applies it (not for
// IMREAD_UNCHANGED). Other flags and 4-component (CMYK) JPEGs are decoded once here, to find
// damage, then by cv::imdecode. Nothing is printed. Throws arview::Error naming `name`:
// "<name>: damaged JPEG data (libjpeg: <its warning>)" for damage inside the data, and
// "<name>: cannot be decoded as a JPEG (libjpeg: <its error>)" when libjpeg gives up.
cv::Mat DecodeJpeg(std::string_view bytes, const std::string& name, int imread_flags,
                   JpegDamage damage = JpegDamage::kRefuse);

}  // namespace arview
