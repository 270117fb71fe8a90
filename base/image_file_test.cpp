#include "base/image_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <zlib.h>

#include "base/error.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("arview_image_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(WriteImageAtomically, WritesAPngThatReadsBackExactly) {
  const fs::path dir = TempDir("png");
  cv::Mat image(4, 5, CV_8UC3);
  cv::randu(image, 0, 255);
  WriteImageAtomically(dir / "a.png", image);
  const cv::Mat back = cv::imread((dir / "a.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), {}), 1);
  fs::remove_all(dir);
}

TEST(WriteImageAtomically, AnUnknownExtensionOrAnEmptyImageThrowsNamingTheFile) {
  const fs::path dir = TempDir("bad");
  cv::Mat image(2, 2, CV_8UC1, cv::Scalar(7));
  for (const fs::path& file : {dir / "a.nosuchformat", dir / "noextension"}) {
    try {
      WriteImageAtomically(file, image);
      FAIL() << "expected an error for " << file;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(WriteImageAtomically(dir / "empty.png", cv::Mat()), Error);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), {}), 0);
  fs::remove_all(dir);
}


std::string Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void Write(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// Returns the message of the Error ReadImageFile throws, and what was printed on stderr
// meanwhile (libpng prints its own "libpng error: ..." line unless the check comes first).
std::pair<std::string, std::string> ReadFailure(const fs::path& file) {
  std::string message;
  ::testing::internal::CaptureStderr();
  try {
    (void)ReadImageFile(file, cv::IMREAD_COLOR);
  } catch (const Error& e) {
    message = e.what();
  }
  return {message, ::testing::internal::GetCapturedStderr()};
}

TEST(ReadImageFile, ReadsWhatImreadReads) {
  const fs::path dir = TempDir("read");
  cv::Mat image(6, 7, CV_8UC3);
  cv::randu(image, 0, 255);
  cv::imwrite((dir / "a.png").string(), image);
  EXPECT_EQ(cv::norm(ReadImageFile(dir / "a.png", cv::IMREAD_COLOR), image, cv::NORM_INF), 0);
  fs::remove_all(dir);
}

// Issue 17: a truncated PNG frame printed libpng's own line before ours.
TEST(ReadImageFile, ATruncatedPngIsOneErrorNamingTheFileAndLibpngSaysNothing) {
  const fs::path dir = TempDir("truncated");
  cv::Mat image(64, 64, CV_8UC3);
  cv::randu(image, 0, 255);
  cv::imwrite((dir / "whole.png").string(), image);
  const std::string whole = Bytes(dir / "whole.png");
  for (size_t keep : {size_t{0}, size_t{7}, size_t{30}, whole.size() / 2, whole.size() - 1}) {
    const fs::path cut = dir / ("cut" + std::to_string(keep) + ".png");
    Write(cut, whole.substr(0, keep));
    const auto [message, printed] = ReadFailure(cut);
    EXPECT_EQ(message.rfind(cut.string() + ": ", 0), 0u) << keep << ": " << message;
    EXPECT_EQ(printed, "") << keep;
  }
  fs::remove_all(dir);
}

// Issue 17: a 65535x65535 PNG header printed OpenCV's internal assertion text.
TEST(ReadImageFile, AHugeOrZeroPngHeaderIsRefusedBeforeDecoding) {
  const fs::path dir = TempDir("huge");
  cv::Mat image(8, 8, CV_8UC1, cv::Scalar(3));
  cv::imwrite((dir / "small.png").string(), image);
  const std::string small = Bytes(dir / "small.png");
  for (const char* size : {"\xff\xff", "\x00\x00"}) {
    std::string mutated = small;
    // IHDR's width and height: big-endian 32-bit at bytes 16 and 20.
    mutated.replace(18, 2, size, 2);
    mutated.replace(22, 2, size, 2);
    const fs::path file = dir / "mutated.png";
    Write(file, mutated);
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string() + ": the image header says ", 0), 0u) << message;
    EXPECT_EQ(printed, "");
  }
  fs::remove_all(dir);
}

// A JPEG as OpenCV (libjpeg) writes one: SOI, APP0, DQT, SOF0, DHT, SOS, data, EOI.
std::string SmallJpeg(int width = 64, int height = 48) {
  cv::Mat image(height, width, CV_8UC3);
  cv::randu(image, 0, 255);
  std::vector<unsigned char> encoded;
  EXPECT_TRUE(cv::imencode(".jpg", image, encoded, {cv::IMWRITE_JPEG_QUALITY, 90}));
  return {encoded.begin(), encoded.end()};
}

// Where marker 0xFF `marker` starts (its 0xFF), searched from the start.
size_t FindMarker(const std::string& jpeg, unsigned char marker) {
  const size_t at = jpeg.find(std::string{'\xff', static_cast<char>(marker)});
  EXPECT_NE(at, std::string::npos) << "marker " << int{marker};
  return at;
}

// Issue 17: libjpeg printed "Premature end of JPEG file" (and "Corrupt JPEG data: premature end
// of data segment") for a cut frame, while OpenCV went on decoding it.
TEST(ReadImageFile, ATruncatedJpegIsOneErrorNamingTheFileAndLibjpegSaysNothing) {
  const fs::path dir = TempDir("jpeg_truncated");
  const std::string whole = SmallJpeg();
  const size_t scan = FindMarker(whole, 0xda);
  for (size_t keep : {size_t{3}, size_t{4}, size_t{12}, FindMarker(whole, 0xc0) + 6, scan + 5, scan + 20,
                      (scan + whole.size()) / 2, whole.size() - 2, whole.size() - 1}) {
    const fs::path cut = dir / ("cut" + std::to_string(keep) + ".jpg");
    Write(cut, whole.substr(0, keep));
    const auto [message, printed] = ReadFailure(cut);
    EXPECT_EQ(message.rfind(cut.string() + ": the JPEG is cut short", 0), 0u) << keep << ": " << message;
    EXPECT_EQ(printed, "") << keep;
  }
  fs::remove_all(dir);
}

TEST(ReadImageFile, ADamagedJpegHeaderIsRefusedBeforeLibjpeg) {
  const fs::path dir = TempDir("jpeg_damaged");
  const std::string whole = SmallJpeg();
  const size_t dqt = FindMarker(whole, 0xdb), sof = FindMarker(whole, 0xc0), sos = FindMarker(whole, 0xda);
  std::vector<std::pair<std::string, std::string>> cases;  // (bytes, the start of the expected reason)
  // Bytes between two segments: libjpeg warns "Corrupt JPEG data: 3 extraneous bytes before
  // marker 0xdb" and decodes anyway.
  cases.push_back({whole.substr(0, dqt) + "abc" + whole.substr(dqt), "not a valid JPEG (no marker where one must start"});
  // A segment length one too long: the next segment's marker is read as the segment's data.
  std::string longer = whole;
  longer[dqt + 3] = static_cast<char>(longer[dqt + 3] + 1);
  cases.push_back({longer, "not a valid JPEG (no marker where one must start"});
  // A frame header that names one more component than it holds.
  std::string components = whole;
  components[sof + 9] = static_cast<char>(components[sof + 9] + 1);
  cases.push_back({components, "not a valid JPEG (a frame header whose length does not match"});
  // A scan header without components.
  std::string scan = whole;
  scan[sos + 4] = 0;
  cases.push_back({scan, "not a valid JPEG (a scan header whose length does not match"});
  // A baseline scan whose spectral end is not 63 (libjpeg: "Invalid SOS parameters for
  // sequential JPEG"; found by fuzz_image).
  std::string spectrum = whole;
  const size_t sos_length = (size_t{static_cast<unsigned char>(whole[sos + 2])} << 8) | static_cast<unsigned char>(whole[sos + 3]);
  spectrum[sos + 2 + sos_length - 2] = 62;
  cases.push_back({spectrum, "not a valid JPEG (a sequential scan header with progressive parameters"});
  // The frame header removed: the scan comes first.
  const size_t sof_length = (size_t{static_cast<unsigned char>(whole[sof + 2])} << 8) | static_cast<unsigned char>(whole[sof + 3]);
  cases.push_back({whole.substr(0, sof) + whole.substr(sof + 2 + sof_length), "not a valid JPEG (a scan before the frame header"});
  // Sizes OpenCV or libjpeg refuse with their own text: 0 rows, 65535x65535.
  for (const char* size : {"\x00\x00", "\xff\xff"}) {
    std::string mutated = whole;
    mutated.replace(sof + 5, 2, size, 2);  // height
    mutated.replace(sof + 7, 2, "\xff\xff", 2);  // width
    cases.push_back({mutated, "the image header says "});
  }
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path file = dir / ("damaged" + std::to_string(i) + ".jpg");
    Write(file, cases[i].first);
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string() + ": " + cases[i].second, 0), 0u) << i << ": " << message;
    EXPECT_EQ(printed, "") << i;
  }
  fs::remove_all(dir);
}

// Cameras may write data after EOI (a second image, maker notes): it is not a damaged file.
TEST(ReadImageFile, AJpegWithDataAfterItsEoiMarkerIsReadAsItsImage) {
  const fs::path dir = TempDir("jpeg_trailer");
  const std::string whole = SmallJpeg(40, 30);
  Write(dir / "plain.jpg", whole);
  Write(dir / "trailer.jpg", whole + std::string("\x00\xff\xd8\xff\xe1 trailing maker data \xff", 26));
  const cv::Mat expected = cv::imread((dir / "plain.jpg").string(), cv::IMREAD_COLOR);
  ::testing::internal::CaptureStderr();
  const cv::Mat read = ReadImageFile(dir / "trailer.jpg", cv::IMREAD_COLOR);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(read.size(), cv::Size(40, 30));
  EXPECT_EQ(cv::norm(read, expected, cv::NORM_INF), 0);
  fs::remove_all(dir);
}

// Issue 17: a PNG whose structure is complete but whose bytes are damaged made libpng print its
// own line ("IDAT: incorrect data check", "bad adaptive filter value", "IHDR: CRC error", ...,
// seen by fuzz_image). Every chunk's CRC is checked first.
TEST(ReadImageFile, APngWithADamagedChunkIsRefusedBeforeLibpng) {
  const fs::path dir = TempDir("png_damaged");
  cv::Mat image(32, 48, CV_8UC3);
  cv::randu(image, 0, 255);
  cv::imwrite((dir / "whole.png").string(), image);
  const std::string whole = Bytes(dir / "whole.png");
  const size_t idat = whole.find("IDAT") - 4;
  std::vector<std::pair<std::string, std::string>> cases;  // (bytes, the start of the expected reason)
  for (size_t at : {idat + 8 + 2, idat + 8 + 40, whole.size() - 12 - 6}) {  // inside the compressed data
    std::string flipped = whole;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x10);
    cases.push_back({flipped, "not a valid PNG (the CRC of its IDAT chunk does not match"});
  }
  std::string crc = whole;  // IHDR's CRC itself
  crc[29] = static_cast<char>(crc[29] ^ 1);
  cases.push_back({crc, "not a valid PNG (the CRC of its IHDR chunk does not match"});
  std::string type = whole;
  type[idat + 5] = '?';
  cases.push_back({type, "not a valid PNG (a chunk type that is not four letters"});
  std::string length = whole;
  length[idat + 1] = 0x70;  // IDAT's length, now past the end
  cases.push_back({length, "not a valid PNG (a chunk longer than the file"});
  std::string depth = whole;
  depth[24] = 3;  // bit depth 3, with its CRC recomputed: a valid chunk with a wrong field
  const auto ihdr_crc = static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const unsigned char*>(depth.data()) + 12, 17));
  for (int i = 0; i < 4; ++i) depth[29 + i] = static_cast<char>(ihdr_crc >> (24 - 8 * i));
  cases.push_back({depth, "not a valid PNG (an IHDR header with invalid fields"});
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path file = dir / ("damaged" + std::to_string(i) + ".png");
    Write(file, cases[i].first);
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string() + ": " + cases[i].second, 0), 0u) << i << ": " << message;
    EXPECT_EQ(printed, "") << i;
  }
  fs::remove_all(dir);
}

// The checks must not refuse what cameras and encoders write: every real frame at hand (the
// phone video's JPEG frames, templeRing's PNG photos, OpenCV's sample photos) is read, libjpeg
// and libpng printing nothing, each with exactly cv::imread's pixels.
TEST(ReadImageFile, EveryRealFrameAtHandPassesTheChecks) {
  const fs::path phone = testing::SharedData("phone-fox/images"), temple = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(phone, "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH(temple, "../shared/data");
  std::vector<fs::path> files;
  size_t jpegs = 0, pngs = 0;
  for (const fs::path& folder : {phone, temple, fs::path("/usr/share/doc/opencv-doc/examples/data")}) {
    if (!fs::is_directory(folder)) continue;
    for (const auto& entry : fs::directory_iterator(folder)) {
      std::string extension = entry.path().extension().string();
      std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
      if (extension == ".jpg" || extension == ".jpeg") ++jpegs;
      else if (extension == ".png") ++pngs;
      else continue;
      files.push_back(entry.path());
    }
  }
  EXPECT_GE(jpegs, 67u);
  EXPECT_GE(pngs, 47u);
  for (const fs::path& file : files) {
    ::testing::internal::CaptureStderr();
    try {
      // The same pixels as cv::imread (JPEGs and PNGs are decoded by our own libjpeg and libpng calls).
      const cv::Mat image = ReadImageFile(file, cv::IMREAD_COLOR);
      const cv::Mat expected = cv::imread(file.string(), cv::IMREAD_COLOR);
      ASSERT_EQ(image.size(), expected.size()) << file;
      EXPECT_EQ(cv::norm(image, expected, cv::NORM_INF), 0) << file;
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
    }
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << file;
  }
}

TEST(ReadImageFile, NotAnImageADirectoryAndAnEmptyFileNameTheFile) {
  const fs::path dir = TempDir("notimage");
  Write(dir / "text.png", "hello, not a picture");
  Write(dir / "empty.png", "");
  for (const fs::path& file : {dir / "text.png", dir / "empty.png", dir / "missing.png", dir}) {
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string(), 0), 0u) << message;
    EXPECT_EQ(printed, "") << file;
  }
  fs::remove_all(dir);
}

// fuzz_image (libFuzzer, stop 23): neither PNG nor JPEG (a PNG signature with a byte dropped) and
// "DICM" at offset 128, so cv::imdecode handed it to GDCM's DICOM reader, whose assert aborted the
// process. Only PNG, JPEG, BMP, TIFF and PNM reach a decoder now.
TEST(ReadImageFile, AFileOfAnotherFormatIsRefusedBeforeOpenCvsDecodersSeeIt) {
  const fs::path dir = TempDir("otherformat");
  const std::string campaign_input(
      "\x89\x50\x4e\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x70\x91\x83\x9b"
      "\x29\x94\x6a\x53\x65\xa5\x6c\x30\xec\xc2\x5c\x16\x56\x59\x8b\x0b\x1f\x5d\x83\xd3\x51\xcb\xc7\x6b"
      "\x89\x44\x49\x43\x4d\x0d\x49\xda\x72\x19\xc7\x01\x72\xdc\x79\xed\x07\xd2\x1a\x82\x4a\x94\xbd\xd3"
      "\x84\x5f\xc5\x44\x49\x43\x4d\x32\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff"
      "\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff"
      "\xff\xff\xff\xff\xff\xff\xff\xff\x44\x49\x43\x4d",
      132);
  std::string dicom(128, '\0');
  dicom += "DICM";
  dicom += std::string(64, '\xff');
  Write(dir / "campaign.png", campaign_input);
  Write(dir / "dicom.png", dicom);
  for (const fs::path& file : {dir / "campaign.png", dir / "dicom.png"}) {
    const auto [message, printed] = ReadFailure(file);
    EXPECT_EQ(message.rfind(file.string() + ": not a PNG, JPEG, BMP, TIFF or PNM image", 0), 0u) << message;
    EXPECT_EQ(printed, "") << file;
  }
  // The other formats still read.
  cv::Mat image(6, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  for (const char* extension : {".bmp", ".tif", ".ppm"}) {
    const fs::path file = dir / (std::string("image") + extension);
    ASSERT_TRUE(cv::imwrite(file.string(), image)) << extension;
    const cv::Mat read = ReadImageFile(file, cv::IMREAD_COLOR);
    EXPECT_EQ(cv::norm(read, image, cv::NORM_INF), 0.0) << extension;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
