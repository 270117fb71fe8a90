#include "recordings/image_metadata.h"

#include <libexif/exif-data.h>

#include <cmath>
#include <memory>
#include <sstream>

namespace arview::recordings {
namespace {

constexpr double kFullFrameDiagonalMm = 43.2666;  // sqrt(36² + 24²)
constexpr double kWidestFovDeg = 170;

using ExifDataPtr = std::unique_ptr<ExifData, decltype(&exif_data_unref)>;

ExifEntry* FindTag(ExifData* data, ExifTag tag) {
  for (ExifIfd ifd : {EXIF_IFD_EXIF, EXIF_IFD_0}) {
    if (ExifEntry* e = exif_content_get_entry(data->ifd[ifd], tag)) return e;
  }
  return nullptr;
}

std::optional<double> ShortValue(ExifData* data, ExifTag tag) {
  ExifEntry* e = FindTag(data, tag);
  if (!e || e->format != EXIF_FORMAT_SHORT || e->components < 1 || e->size < 2) return std::nullopt;
  return exif_get_short(e->data, exif_data_get_byte_order(data));
}

std::optional<double> WholeValue(ExifData* data, ExifTag tag) {
  ExifEntry* e = FindTag(data, tag);
  if (e && e->format == EXIF_FORMAT_LONG && e->components >= 1 && e->size >= 4)
    return exif_get_long(e->data, exif_data_get_byte_order(data));
  return ShortValue(data, tag);
}

std::optional<double> RationalValue(ExifData* data, ExifTag tag) {
  ExifEntry* e = FindTag(data, tag);
  if (!e || e->format != EXIF_FORMAT_RATIONAL || e->components < 1 || e->size < 8) return std::nullopt;
  const ExifRational r = exif_get_rational(e->data, exif_data_get_byte_order(data));
  if (r.denominator == 0) return std::nullopt;
  return static_cast<double>(r.numerator) / r.denominator;
}

std::string Text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The focal length fits a field of view of at most kWidestFovDeg across the longer side.
bool PlausibleFocal(double focal_px, int width, int height) {
  const double min_focal = std::max(width, height) / 2.0 / std::tan(kWidestFovDeg * M_PI / 360.0);
  return std::isfinite(focal_px) && focal_px >= min_focal && focal_px <= 1e6;
}

}  // namespace

std::optional<FocalFromMetadata> ReadFocalFromExif(const std::filesystem::path& image, int width, int height,
                                                   std::string* ignored) {
  ExifDataPtr data(exif_data_new_from_file(image.c_str()), &exif_data_unref);
  if (!data) return std::nullopt;
  const std::string where = image.string() + ": EXIF ";
  const double diagonal_px = std::hypot(width, height);
  if (const std::optional<double> f35 = ShortValue(data.get(), EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM); f35 && *f35 > 0) {
    const double focal_px = *f35 / kFullFrameDiagonalMm * diagonal_px;
    if (*f35 >= 4 && *f35 <= 2000 && PlausibleFocal(focal_px, width, height))
      return FocalFromMetadata{focal_px, "EXIF FocalLengthIn35mmFilm " + Text(*f35) + " mm (on the diagonal)"};
    if (ignored) *ignored = where + "FocalLengthIn35mmFilm " + Text(*f35) + " mm is not a camera's (4 to 2000 mm): ignored";
    return std::nullopt;
  }
  const std::optional<double> focal_mm = RationalValue(data.get(), EXIF_TAG_FOCAL_LENGTH);
  const std::optional<double> plane_x = RationalValue(data.get(), EXIF_TAG_FOCAL_PLANE_X_RESOLUTION);
  if (!focal_mm || !plane_x) return std::nullopt;
  // FocalPlaneResolutionUnit: 2 inch (the default), 3 centimetre, 4 millimetre, 5 micrometre.
  const std::optional<double> unit = ShortValue(data.get(), EXIF_TAG_FOCAL_PLANE_RESOLUTION_UNIT);
  const double mm_per_unit = !unit || *unit == 2 ? 25.4 : *unit == 3 ? 10.0 : *unit == 4 ? 1.0 : *unit == 5 ? 1e-3 : 0.0;
  // The focal plane's resolution is that of the image the camera wrote (PixelXDimension wide);
  // a resized copy has its focal length scaled with it.
  const std::optional<double> written_x = WholeValue(data.get(), EXIF_TAG_PIXEL_X_DIMENSION);
  const std::optional<double> written_y = WholeValue(data.get(), EXIF_TAG_PIXEL_Y_DIMENSION);
  const double written_longer = std::max(written_x.value_or(0.0), written_y.value_or(0.0));
  const double resize = written_longer > 0 ? std::max(width, height) / written_longer : 1.0;
  const double focal_px = mm_per_unit > 0 ? *focal_mm * *plane_x / mm_per_unit * resize : 0.0;
  if (mm_per_unit > 0 && *focal_mm > 0 && *plane_x > 0 && PlausibleFocal(focal_px, width, height)) {
    return FocalFromMetadata{focal_px, "EXIF FocalLength " + Text(*focal_mm) + " mm at FocalPlaneXResolution " +
                                           Text(*plane_x) + " per " + Text(mm_per_unit) + " mm"};
  }
  if (ignored) {
    *ignored = where + "FocalLength " + Text(*focal_mm) + " mm with FocalPlaneXResolution " + Text(*plane_x) +
               (mm_per_unit > 0 ? "" : " in an unknown unit") + " gives no camera's focal length: ignored";
  }
  return std::nullopt;
}

}  // namespace arview::recordings
