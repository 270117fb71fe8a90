#include "base/png_decoder.h"

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/image_file.h"
#include "tests/support/test_picture.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

cv::Mat Picture(int width, int height) { return testing::PhotoLikePicture(width, height); }

std::string Imencode(const cv::Mat& image) {
  std::vector<unsigned char> encoded;
  EXPECT_TRUE(cv::imencode(".png", image, encoded));
  return {encoded.begin(), encoded.end()};
}

// What the test writes with libpng itself: the kinds cv::imwrite does not write (gray+alpha,
// palettes, 1/2/4-bit gray, tRNS, Adam7 interlacing, an eXIf chunk). The samples are random
// bytes, packed as the format stores them; palettes have an entry for every index.
struct PngKind {
  std::string label;
  int width = 13, height = 11;  // not multiples of Adam7's 8x8 block
  int bit_depth = 8;
  int colour_type = PNG_COLOR_TYPE_GRAY;
  bool interlaced = false;
  bool trns = false;   // palette: alpha for the first half of the entries; gray, RGB: one colour
  std::string exif;    // an eXIf chunk's TIFF block, when not empty
};

PngKind Kind(std::string label, int width, int height, int bit_depth, int colour_type, bool interlaced = false,
             bool trns = false) {
  PngKind kind;
  kind.label = std::move(label);
  kind.width = width;
  kind.height = height;
  kind.bit_depth = bit_depth;
  kind.colour_type = colour_type;
  kind.interlaced = interlaced;
  kind.trns = trns;
  return kind;
}

int ChannelsOf(int colour_type) {
  switch (colour_type) {
    case PNG_COLOR_TYPE_GRAY_ALPHA: return 2;
    case PNG_COLOR_TYPE_RGB: return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA: return 4;
    default: return 1;
  }
}

void AppendToString(png_structp png, png_bytep data, size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

std::string WritePng(const PngKind& kind, unsigned seed = 1) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    ADD_FAILURE() << "libpng could not write " << kind.label;
    return {};
  }
  png_set_write_fn(png, &out, AppendToString, nullptr);
  png_set_IHDR(png, info, kind.width, kind.height, kind.bit_depth, kind.colour_type,
               kind.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  cv::RNG rng(seed);
  const int entries = 1 << kind.bit_depth;
  std::vector<png_color> palette(kind.colour_type == PNG_COLOR_TYPE_PALETTE ? entries : 0);
  for (png_color& c : palette) c = {static_cast<png_byte>(rng.uniform(0, 256)), static_cast<png_byte>(rng.uniform(0, 256)),
                                    static_cast<png_byte>(rng.uniform(0, 256))};
  if (!palette.empty()) png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  std::vector<png_byte> alpha;
  png_color_16 transparent{};
  const unsigned max_sample = (1u << kind.bit_depth) - 1;
  if (kind.trns) {
    if (kind.colour_type == PNG_COLOR_TYPE_PALETTE) {
      for (int i = 0; i < std::max(1, entries / 2); ++i) alpha.push_back(static_cast<png_byte>(rng.uniform(0, 256)));
    } else {
      transparent.gray = static_cast<png_uint_16>(max_sample / 3);
      transparent.red = static_cast<png_uint_16>(max_sample / 5);
      transparent.green = static_cast<png_uint_16>(max_sample / 7);
      transparent.blue = static_cast<png_uint_16>(max_sample / 2);
    }
    png_set_tRNS(png, info, alpha.empty() ? nullptr : alpha.data(), static_cast<int>(alpha.size()), &transparent);
  }
  if (!kind.exif.empty()) {
    png_set_eXIf_1(png, info, static_cast<png_uint_32>(kind.exif.size()),
                   reinterpret_cast<png_bytep>(const_cast<char*>(kind.exif.data())));
  }
  png_write_info(png, info);
  const size_t row_bytes = (static_cast<size_t>(kind.width) * ChannelsOf(kind.colour_type) * kind.bit_depth + 7) / 8;
  std::vector<png_byte> samples(row_bytes * kind.height);
  for (png_byte& b : samples) b = static_cast<png_byte>(rng.uniform(0, 256));
  if (kind.trns && kind.colour_type != PNG_COLOR_TYPE_PALETTE && kind.bit_depth == 8) {
    // Some pixels of the transparent colour, so that tRNS makes a difference.
    const int channels = ChannelsOf(kind.colour_type);
    for (size_t at = 0; at + channels <= samples.size(); at += channels * 5) {
      if (channels == 1) samples[at] = static_cast<png_byte>(transparent.gray);
      else samples[at] = static_cast<png_byte>(transparent.red), samples[at + 1] = static_cast<png_byte>(transparent.green),
           samples[at + 2] = static_cast<png_byte>(transparent.blue);
    }
  }
  std::vector<png_bytep> rows(kind.height);
  for (int y = 0; y < kind.height; ++y) rows[y] = samples.data() + row_bytes * y;
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return out;
}

// What cv::imdecode gives, and what libpng printed on stderr meanwhile.
std::pair<cv::Mat, std::string> Imdecode(const std::string& png, int flags) {
  ::testing::internal::CaptureStderr();
  cv::Mat image = cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()), flags);
  return {image, ::testing::internal::GetCapturedStderr()};
}

// DecodePng's image, or its error's text; and what was printed on stderr meanwhile.
struct Decoded {
  cv::Mat image;
  std::string error;
  std::string printed;
};

Decoded Decode(const std::string& png, const std::string& name, int flags) {
  Decoded d;
  ::testing::internal::CaptureStderr();
  try {
    d.image = DecodePng(png, name, flags);
  } catch (const Error& e) {
    d.error = e.what();
  }
  d.printed = ::testing::internal::GetCapturedStderr();
  return d;
}

void ExpectSameImage(const cv::Mat& ours, const cv::Mat& opencv, const std::string& what) {
  ASSERT_FALSE(opencv.empty()) << what;
  ASSERT_FALSE(ours.empty()) << what;
  ASSERT_EQ(ours.size(), opencv.size()) << what;
  ASSERT_EQ(ours.type(), opencv.type()) << what;
  EXPECT_EQ(cv::norm(ours, opencv, cv::NORM_INF), 0) << what;
}

// Every flag our callers use (COLOR: frames, textures; GRAYSCALE: calibration photos;
// UNCHANGED: import), the other combinations imread knows, and one this decoder hands on to
// cv::imdecode after its own decode (a reduced size).
constexpr int kFlags[] = {cv::IMREAD_COLOR,
                          cv::IMREAD_GRAYSCALE,
                          cv::IMREAD_UNCHANGED,
                          cv::IMREAD_ANYDEPTH,
                          cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH,
                          cv::IMREAD_ANYCOLOR,
                          cv::IMREAD_ANYCOLOR | cv::IMREAD_ANYDEPTH,
                          cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION,
                          cv::IMREAD_REDUCED_COLOR_2};

std::vector<std::pair<std::string, std::string>> EveryKindOfPng() {
  std::vector<std::pair<std::string, std::string>> pngs;
  const cv::Mat picture = Picture(13, 11);
  cv::Mat grey, bgra, deep;
  cv::cvtColor(picture, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(picture, bgra, cv::COLOR_BGR2BGRA);
  std::vector<cv::Mat> planes;
  cv::split(bgra, planes);
  cv::randu(planes[3], 0, 256);
  cv::merge(planes, bgra);
  // OpenCV's encoder: 8-bit gray, BGR, BGRA; 16-bit gray, BGR, BGRA.
  pngs.emplace_back("imwrite gray 8", Imencode(grey));
  pngs.emplace_back("imwrite BGR 8", Imencode(picture));
  pngs.emplace_back("imwrite BGRA 8", Imencode(bgra));
  for (const cv::Mat& m : {grey, picture, bgra}) {
    m.convertTo(deep, CV_16U, 257.3);
    cv::Mat noise(deep.size(), deep.type());
    cv::randu(noise, 0, 200);
    pngs.emplace_back("imwrite " + std::to_string(m.channels()) + " channels 16", Imencode(deep - noise));
  }
  // libpng: every other colour type, bit depth, transparency and Adam7.
  std::vector<PngKind> kinds;
  for (int depth : {1, 2, 4, 8, 16}) {
    kinds.push_back(Kind("gray " + std::to_string(depth), 13, 11, depth, PNG_COLOR_TYPE_GRAY));
    kinds.push_back(Kind("gray " + std::to_string(depth) + " tRNS", 13, 11, depth, PNG_COLOR_TYPE_GRAY, false, true));
    if (depth <= 8) {
      kinds.push_back(Kind("palette " + std::to_string(depth), 13, 11, depth, PNG_COLOR_TYPE_PALETTE));
      kinds.push_back(Kind("palette " + std::to_string(depth) + " tRNS", 13, 11, depth, PNG_COLOR_TYPE_PALETTE, false, true));
    } else {
      kinds.push_back(Kind("gray+alpha 16", 13, 11, 16, PNG_COLOR_TYPE_GRAY_ALPHA));
      kinds.push_back(Kind("RGB 16 tRNS", 13, 11, 16, PNG_COLOR_TYPE_RGB, false, true));
      kinds.push_back(Kind("RGBA 16", 13, 11, 16, PNG_COLOR_TYPE_RGB_ALPHA));
    }
  }
  kinds.push_back(Kind("gray+alpha 8", 13, 11, 8, PNG_COLOR_TYPE_GRAY_ALPHA));
  kinds.push_back(Kind("RGB 8", 13, 11, 8, PNG_COLOR_TYPE_RGB));
  kinds.push_back(Kind("RGB 8 tRNS", 13, 11, 8, PNG_COLOR_TYPE_RGB, false, true));
  kinds.push_back(Kind("RGBA 8", 13, 11, 8, PNG_COLOR_TYPE_RGB_ALPHA));
  std::vector<PngKind> interlaced;
  for (PngKind kind : kinds) {
    kind.label += " Adam7";
    kind.interlaced = true;
    interlaced.push_back(kind);
  }
  kinds.insert(kinds.end(), interlaced.begin(), interlaced.end());
  // Images smaller than Adam7's block, where some passes are empty.
  kinds.push_back(Kind("RGB 8 Adam7 1x1", 1, 1, 8, PNG_COLOR_TYPE_RGB, true));
  kinds.push_back(Kind("palette 2 tRNS Adam7 3x2", 3, 2, 2, PNG_COLOR_TYPE_PALETTE, true, true));
  kinds.push_back(Kind("gray+alpha 8 Adam7 5x1", 5, 1, 8, PNG_COLOR_TYPE_GRAY_ALPHA, true));
  for (const PngKind& kind : kinds) pngs.emplace_back(kind.label, WritePng(kind));
  return pngs;
}

TEST(DecodePng, GivesImdecodesPixelsForEveryKindOfPngAndFlag) {
  const auto pngs = EveryKindOfPng();
  ASSERT_GE(pngs.size(), 50u);
  for (const auto& [kind, png] : pngs) {
    for (int flags : kFlags) {
      const std::string what = kind + ", flags " + std::to_string(flags);
      cv::Mat expected;
      std::string printed;
      try {
        std::tie(expected, printed) = Imdecode(png, flags);
      } catch (const cv::Exception& e) {
        // A reduced size of a 1-pixel image: OpenCV's resize asserts; ours is that assertion, named.
        (void)::testing::internal::GetCapturedStderr();
        const Decoded ours = Decode(png, "a.png", flags);
        EXPECT_EQ(ours.error.rfind("a.png: cannot be decoded as an image (", 0), 0u) << what << ": " << ours.error;
        continue;
      }
      ASSERT_EQ(printed, "") << what;
      const Decoded ours = Decode(png, "a.png", flags);
      EXPECT_EQ(ours.error, "") << what;
      EXPECT_EQ(ours.printed, "") << what;
      ExpectSameImage(ours.image, expected, what);
    }
  }
}

// An eXIf chunk holding one IFD entry, Orientation (0x0112, SHORT, 1) = `orientation`.
std::string ExifTiff(unsigned orientation, bool little_endian) {
  const auto u16 = [&](unsigned v) {
    return little_endian ? std::string{static_cast<char>(v & 0xff), static_cast<char>(v >> 8)}
                         : std::string{static_cast<char>(v >> 8), static_cast<char>(v & 0xff)};
  };
  const auto u32 = [&](unsigned v) { return little_endian ? u16(v & 0xffff) + u16(v >> 16) : u16(v >> 16) + u16(v & 0xffff); };
  return (little_endian ? "II" : "MM") + u16(42) + u32(8) + u16(1) + u16(0x0112) + u16(3) + u32(1) + u16(orientation) +
         u16(0) + u32(0);
}

// OpenCV 4.6 reads a PNG's eXIf chunk and turns the image upright (for every flag but
// IMREAD_UNCHANGED and those with IMREAD_IGNORE_ORIENTATION), and so must we.
TEST(DecodePng, AppliesTheExifOrientationAsImdecodeDoes) {
  for (bool little_endian : {true, false}) {
    for (unsigned orientation = 0; orientation <= 9; ++orientation) {
      PngKind kind = Kind("RGB 8 eXIf", 9, 6, 8, PNG_COLOR_TYPE_RGB);
      kind.exif = ExifTiff(orientation, little_endian);
      const std::string png = WritePng(kind);
      for (int flags : {int{cv::IMREAD_COLOR}, int{cv::IMREAD_GRAYSCALE}, int{cv::IMREAD_UNCHANGED}, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION}) {
        const std::string what = "orientation " + std::to_string(orientation) + (little_endian ? " II" : " MM") +
                                 ", flags " + std::to_string(flags);
        const auto [expected, printed] = Imdecode(png, flags);
        ASSERT_EQ(printed, "") << what;
        // The test's own check that the chunk is read: orientations 5-8 stand the image up.
        if (orientation >= 5 && orientation <= 8 && (flags == cv::IMREAD_COLOR || flags == cv::IMREAD_GRAYSCALE)) {
          ASSERT_EQ(expected.rows, 9) << what;
        }
        const Decoded ours = Decode(png, "a.png", flags);
        EXPECT_EQ(ours.printed, "") << what;
        ExpectSameImage(ours.image, expected, what);
      }
    }
  }
}

// templeRing's photos (the Middlebury multi-view set, 640x480 RGB), identical to cv::imread.
TEST(DecodePng, EveryTempleRingPhotoGivesImreadsPixels) {
  const fs::path temple = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(temple, "../shared/data");
  size_t pngs = 0;
  for (const auto& entry : fs::directory_iterator(temple)) {
    if (entry.path().extension() != ".png") continue;
    ++pngs;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    for (int flags : {cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE, cv::IMREAD_UNCHANGED}) {
      const Decoded ours = Decode(bytes, entry.path().string(), flags);
      EXPECT_EQ(ours.error, "");
      EXPECT_EQ(ours.printed, "") << entry.path();
      ExpectSameImage(ours.image, cv::imread(entry.path().string(), flags), entry.path().string());
    }
  }
  EXPECT_GE(pngs, 47u);
}

std::uint32_t BigEndian32(const std::string& bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
}

std::string BigEndian32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

// A chunk as a writer makes it: length, type, data, the CRC computed over type and data.
std::string Chunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  const auto crc = static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  return BigEndian32(static_cast<std::uint32_t>(data.size())) + body + BigEndian32(crc);
}

// Where the first chunk of `type` starts, and its data.
std::pair<size_t, std::string> FindChunk(const std::string& png, const std::string& type) {
  for (size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = BigEndian32(png, at);
    if (png.compare(at + 4, 4, type) == 0) return {at, png.substr(at + 8, length)};
    at += 12 + length;
  }
  ADD_FAILURE() << "no " << type << " chunk";
  return {std::string::npos, {}};
}

// The PNG with its first chunk of `type` replaced by `chunks` (CRCs computed as a writer would).
std::string ReplaceChunk(const std::string& png, const std::string& type, const std::string& chunks) {
  const auto [at, data] = FindChunk(png, type);
  return png.substr(0, at) + chunks + png.substr(at + 12 + data.size());
}

fs::path TempFile(const std::string& name) {
  return fs::path(::testing::TempDir()) / ("arview_png_" + std::to_string(::getpid()) + "_" + name);
}

// ReadImageFile on `png` written to a file: its image or error, and what was printed.
Decoded ReadThroughTheReader(const std::string& png, const fs::path& file, int flags = cv::IMREAD_COLOR) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << png;
  Decoded d;
  ::testing::internal::CaptureStderr();
  try {
    d.image = ReadImageFile(file, flags);
  } catch (const Error& e) {
    d.error = e.what();
  }
  d.printed = ::testing::internal::GetCapturedStderr();
  return d;
}

// Issue 17: a PNG written with its CRCs computed over damaged compressed data passes
// ReadImageFile's chunk check, and libpng printed "libpng error: IDAT: invalid distance too far
// back", "libpng warning: IDAT: incorrect data check", ... through OpenCV. A byte changed at 40
// places in the IDAT data, its CRC recomputed: ReadImageFile is one error naming the file and
// quoting libpng, or, where libpng saw nothing, imdecode's image; neither prints anything.
TEST(ReadImageFile, DamagedPngDataUnderARecomputedCrcIsOneErrorNamingTheFileAndLibpngSaysNothing) {
  const fs::path file = TempFile("idat.png");
  const std::string whole = Imencode(Picture(64, 48));
  const auto [idat_at, idat] = FindChunk(whole, "IDAT");
  ASSERT_GT(idat.size(), 100u);
  int refused = 0;
  for (int i = 0; i < 40; ++i) {
    std::string data = idat;
    const size_t at = 2 + (data.size() - 2) * i / 40;  // past the zlib header's two bytes
    data[at] = static_cast<char>(data[at] ^ 0x5a);
    const std::string damaged = ReplaceChunk(whole, "IDAT", Chunk("IDAT", data));
    const auto [expected, libpng_said] = Imdecode(damaged, cv::IMREAD_COLOR);
    const Decoded ours = ReadThroughTheReader(damaged, file);
    EXPECT_EQ(ours.printed, "") << "byte " << at;
    if (ours.error.empty()) {
      EXPECT_EQ(libpng_said, "") << "read although libpng complained, byte " << at;
      ExpectSameImage(ours.image, expected, "byte " + std::to_string(at));
    } else {
      ++refused;
      EXPECT_NE(libpng_said, "") << "refused although libpng saw nothing, byte " << at << ": " << ours.error;
      EXPECT_EQ(ours.error.rfind(file.string() + ": damaged PNG data (libpng: ", 0), 0u) << ours.error;
      EXPECT_EQ(ours.error.find('\n'), std::string::npos) << ours.error;
    }
  }
  // zlib's Adler-32 over the decompressed data catches every change the inflater survives.
  EXPECT_EQ(refused, 40);
  fs::remove(file);
}

// The image data made wrong in the ways the chunk walk accepts (every length inside the file,
// every CRC right): an IDAT cut short, with bytes after the end of the stream, one IDAT too
// many after the image, a tRNS longer than the palette.
// OpenCV's libpng printed an error or a warning for each (and returned an image for the
// warnings); here each is one error naming the file, nothing printed. A damaged metadata chunk
// (a pHYs of the wrong length: libpng warns "pHYs: invalid") is dropped as OpenCV drops it, the
// image read, but silently.
TEST(ReadImageFile, ImageDataTheChunkWalkAcceptsButLibpngRefusesIsOneErrorNamingTheFile) {
  const fs::path file = TempFile("data.png");
  const std::string whole = Imencode(Picture(32, 24));
  const auto [idat_at, idat] = FindChunk(whole, "IDAT");
  const PngKind palette_kind = Kind("palette 8", 16, 8, 8, PNG_COLOR_TYPE_PALETTE);
  const std::string palette_png = WritePng(palette_kind);
  const auto [plte_at, plte] = FindChunk(palette_png, "PLTE");
  const std::string short_palette = ReplaceChunk(palette_png, "PLTE", Chunk("PLTE", plte.substr(0, 3 * 4)));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"an IDAT cut 1 byte short", ReplaceChunk(whole, "IDAT", Chunk("IDAT", idat.substr(0, idat.size() - 1)))},
      {"an IDAT cut 5 bytes short", ReplaceChunk(whole, "IDAT", Chunk("IDAT", idat.substr(0, idat.size() - 5)))},
      {"an IDAT cut to half", ReplaceChunk(whole, "IDAT", Chunk("IDAT", idat.substr(0, idat.size() / 2)))},
      {"an IDAT with 7 bytes after its stream", ReplaceChunk(whole, "IDAT", Chunk("IDAT", idat + "garbage"))},
      {"an IDAT after the image's", ReplaceChunk(whole, "IDAT", Chunk("IDAT", idat) + Chunk("tEXt", std::string("a\0b", 3)) + Chunk("IDAT", idat))},
      {"a tRNS longer than the palette", ReplaceChunk(short_palette, "IDAT", Chunk("tRNS", std::string(6, '\x80')) + Chunk("IDAT", FindChunk(short_palette, "IDAT").second))},
  };
  for (const auto& [what, png] : cases) {
    const auto [expected, libpng_said] = Imdecode(png, cv::IMREAD_COLOR);
    EXPECT_NE(libpng_said, "") << what << ": the test's own check that libpng complains";
    const Decoded ours = ReadThroughTheReader(png, file);
    EXPECT_EQ(ours.printed, "") << what;
    EXPECT_TRUE(ours.image.empty()) << what;
    EXPECT_EQ(ours.error.rfind(file.string() + ": damaged PNG data (libpng: ", 0), 0u) << what << ": " << ours.error;
    EXPECT_EQ(ours.error.find('\n'), std::string::npos) << ours.error;
  }
  const std::string bad_phys = ReplaceChunk(whole, "IDAT", Chunk("pHYs", "12345") + Chunk("IDAT", idat));
  const auto [expected, libpng_said] = Imdecode(bad_phys, cv::IMREAD_COLOR);
  EXPECT_NE(libpng_said.find("pHYs"), std::string::npos) << libpng_said;
  const Decoded ours = ReadThroughTheReader(bad_phys, file);
  EXPECT_EQ(ours.printed, "");
  EXPECT_EQ(ours.error, "");
  ExpectSameImage(ours.image, expected, "a pHYs of 5 bytes");
  fs::remove(file);
}

// DecodePng alone (ReadImageFile's chunk walk refuses these first): a PNG cut at every length
// is one error saying so, nothing printed.
TEST(DecodePng, APngCutAtEveryLengthIsOneErrorSayingSo) {
  for (const std::string& whole : {Imencode(Picture(16, 8)), WritePng(Kind("palette 4 tRNS Adam7", 13, 11, 4, PNG_COLOR_TYPE_PALETTE, true, true))}) {
    for (size_t length = 0; length < whole.size(); ++length) {
      const Decoded ours = Decode(whole.substr(0, length), "cut.png", cv::IMREAD_COLOR);
      EXPECT_EQ(ours.printed, "") << length;
      EXPECT_TRUE(ours.image.empty()) << length;
      EXPECT_EQ(ours.error.rfind("cut.png: the PNG is cut short (its data ends at byte " + std::to_string(length), 0), 0u)
          << length << ": " << ours.error;
    }
  }
}

// What libpng refuses outright, outside the image data (here the signature), is its error text
// after ours; a CRC that does not match (ReadImageFile's walk checks them before) is damage.
TEST(DecodePng, WhatLibpngRefusesIsOneErrorQuotingIt) {
  const std::string whole = Imencode(Picture(16, 8));
  Decoded ours = Decode("\x89PNG\r\n\x1a\x0b" + whole.substr(8), "sig.png", cv::IMREAD_COLOR);
  EXPECT_EQ(ours.printed, "");
  EXPECT_EQ(ours.error.rfind("sig.png: cannot be decoded as a PNG (libpng: ", 0), 0u) << ours.error;
  std::string bad_crc = whole;
  const auto [idat_at, idat] = FindChunk(whole, "IDAT");
  bad_crc[idat_at + 8 + idat.size()] ^= 1;
  ours = Decode(bad_crc, "crc.png", cv::IMREAD_COLOR);
  EXPECT_EQ(ours.printed, "");
  EXPECT_EQ(ours.error, "crc.png: damaged PNG data (libpng: IDAT: CRC error)");
}

}  // namespace
}  // namespace arview
