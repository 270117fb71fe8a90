#pragma once
// Images written atomically: encoded in memory by OpenCV (the format chosen by the file's
// extension, as cv::imwrite does), then written with WriteFileAtomically. The header names
// cv::Mat only, so modules that include base/ without OpenCV (anim/) do not see OpenCV.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace cv {
class Mat;
}

namespace arview {

// Throws arview::Error naming `file` if the extension has no encoder, the image is empty or the
// encoding or the write fails. `params` are cv::imwrite's (e.g. IMWRITE_PNG_COMPRESSION, 1).
void WriteImageAtomically(const std::filesystem::path& file, const cv::Mat& image, const std::vector<int>& params = {});

// Largest image a frame may be: a side of at most 32768 pixels, at most 2^28 pixels in all
// (an 8K frame is 2^25). OpenCV's own limit (2^30) is enforced by an assertion whose text is
// not a message for a user.
inline constexpr long long kMaxImageSide = 32768;
inline constexpr long long kMaxImagePixels = 1ll << 28;

// Reads an image file as cv::imread(file, imread_flags) would, but with one clear error
// (arview::Error naming the file) for every way it can fail, and nothing printed by libpng or
// libjpeg: not a regular file or over kMaxImageFileBytes; a PNG whose signature, IHDR header or
// size is wrong, that is cut short (no IEND chunk at its end) or damaged (a chunk's length past
// the end, its type not letters, its CRC wrong, which catches damage inside the compressed data);
// a JPEG whose marker segments are damaged (a length past the end, bytes where a marker must be,
// a frame header that does not add up, a scan without data), whose size is wrong or that is cut
// short (no EOI marker after its last scan; data after EOI is accepted), all checked before
// libpng/libjpeg see the file; a JPEG whose entropy-coded data is damaged (libjpeg's warning,
// kept in our message: base/jpeg_decoder.h); a PNG whose compressed data, rows or palette are
// damaged under intact CRCs (libpng's error or warning, kept in our message:
// base/png_decoder.h); an image OpenCV cannot decode or refuses (its exception text is kept
// after ours). Never returns an empty image.
cv::Mat ReadImageFile(const std::filesystem::path& file, int imread_flags);

// The same for an image already in memory (a texture embedded in an asset), `name` saying where
// it came from in the errors.
cv::Mat DecodeImageBytes(std::string_view bytes, const std::string& name, int imread_flags);

// cv::imdecode with OpenCV's exception or an empty result as one Error naming `name`; for the
// decoders' last resort, on bytes already checked.
cv::Mat ImdecodeOrThrow(std::string_view bytes, const std::string& name, int imread_flags);

}  // namespace arview
