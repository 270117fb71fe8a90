#pragma once
// A photo's focal length from its EXIF tags (libexif), for importing images without a
// calibration (docs/recordings.md, "Importing without a calibration").

#include <filesystem>
#include <optional>
#include <string>

namespace arview::recordings {

struct FocalFromMetadata {
  double focal_px = 0;      // in pixels of an image of the size given to ReadFocalFromExif
  std::string description;  // what it was computed from, in words
};

// The 35 mm-equivalent focal length (tag FocalLengthIn35mmFilm), or else the focal length in
// mm with the focal plane's resolution (FocalLength, FocalPlaneXResolution and its unit), turned
// into pixels of a width x height image. The 35 mm equivalent is taken on the diagonal (a
// 36 x 24 mm frame's 43.27 mm), as camera makers compute it.
//
// No EXIF, or none of those tags: nullopt. Tags that hold nonsense (a 35 mm equivalent outside
// 4..2000 mm, a zero resolution, a field of view over 170°) also give nullopt, and `*ignored`
// says in one line what was ignored and why.
std::optional<FocalFromMetadata> ReadFocalFromExif(const std::filesystem::path& image, int width, int height,
                                                   std::string* ignored);

}  // namespace arview::recordings
