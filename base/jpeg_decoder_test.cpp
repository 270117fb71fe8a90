#include "base/jpeg_decoder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/image_file.h"
#include "tests/support/test_picture.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

cv::Mat Picture(int width, int height) { return testing::PhotoLikePicture(width, height); }

std::string Encode(const cv::Mat& image, const std::vector<int>& params = {cv::IMWRITE_JPEG_QUALITY, 90}) {
  std::vector<unsigned char> encoded;
  EXPECT_TRUE(cv::imencode(".jpg", image, encoded, params));
  return {encoded.begin(), encoded.end()};
}

// What cv::imdecode gives, and what libjpeg printed on stderr meanwhile.
std::pair<cv::Mat, std::string> Imdecode(const std::string& jpeg, int flags) {
  ::testing::internal::CaptureStderr();
  cv::Mat image = cv::imdecode(std::vector<unsigned char>(jpeg.begin(), jpeg.end()), flags);
  return {image, ::testing::internal::GetCapturedStderr()};
}

void ExpectSameImage(const cv::Mat& ours, const cv::Mat& opencv, const std::string& what) {
  ASSERT_FALSE(opencv.empty()) << what;
  ASSERT_EQ(ours.size(), opencv.size()) << what;
  ASSERT_EQ(ours.type(), opencv.type()) << what;
  EXPECT_EQ(cv::norm(ours, opencv, cv::NORM_INF), 0) << what;
}

constexpr int kFlags[] = {cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE, cv::IMREAD_UNCHANGED};

TEST(DecodeJpeg, GivesImdecodesPixelsForEveryKindOfJpegAndFlag) {
  const cv::Mat picture = Picture(61, 37);  // not a multiple of the 16-pixel MCU
  cv::Mat grey;
  cv::cvtColor(picture, grey, cv::COLOR_BGR2GRAY);
  const std::vector<std::pair<std::string, std::string>> jpegs = {
      {"4:2:0", Encode(picture)},
      // Different luma and chroma qualities make OpenCV's encoder drop chroma subsampling.
      {"4:4:4", Encode(picture, {cv::IMWRITE_JPEG_LUMA_QUALITY, 90, cv::IMWRITE_JPEG_CHROMA_QUALITY, 80})},
      {"progressive", Encode(picture, {cv::IMWRITE_JPEG_PROGRESSIVE, 1})},
      {"restart markers", Encode(picture, {cv::IMWRITE_JPEG_RST_INTERVAL, 2})},
      {"greyscale", Encode(grey)},
  };
  for (const auto& [kind, jpeg] : jpegs) {
    for (int flags : kFlags) {
      const auto [expected, printed] = Imdecode(jpeg, flags);
      ASSERT_EQ(printed, "");
      ExpectSameImage(DecodeJpeg(jpeg, "a.jpg", flags), expected, kind + ", flags " + std::to_string(flags));
    }
  }
}

// An EXIF APP1 segment holding one IFD entry, Orientation (0x0112, SHORT, 1) = `orientation`.
std::string ExifSegment(unsigned orientation, bool little_endian) {
  const auto u16 = [&](unsigned v) {
    return little_endian ? std::string{static_cast<char>(v & 0xff), static_cast<char>(v >> 8)}
                         : std::string{static_cast<char>(v >> 8), static_cast<char>(v & 0xff)};
  };
  const auto u32 = [&](unsigned v) { return little_endian ? u16(v & 0xffff) + u16(v >> 16) : u16(v >> 16) + u16(v & 0xffff); };
  const std::string tiff = (little_endian ? "II" : "MM") + u16(42) + u32(8) + u16(1) + u16(0x0112) + u16(3) + u32(1) +
                           u16(orientation) + u16(0) + u32(0);
  const std::string data = std::string("Exif\0\0", 6) + tiff;
  const size_t length = data.size() + 2;
  return std::string("\xff\xe1", 2) + static_cast<char>(length >> 8) + static_cast<char>(length & 0xff) + data;
}

// Phone photos carry their orientation in EXIF; cv::imdecode turns the image upright (for every
// flag but IMREAD_UNCHANGED), and so must we.
TEST(DecodeJpeg, AppliesTheExifOrientationAsImdecodeDoes) {
  const std::string plain = Encode(Picture(40, 30));
  for (bool little_endian : {true, false}) {
    for (unsigned orientation = 0; orientation <= 9; ++orientation) {
      const std::string jpeg = plain.substr(0, 2) + ExifSegment(orientation, little_endian) + plain.substr(2);
      for (int flags : kFlags) {
        const auto [expected, printed] = Imdecode(jpeg, flags);
        ASSERT_EQ(printed, "");
        // The test's own check that the segment is read: orientations 5-8 stand the image up.
        if (orientation >= 5 && orientation <= 8 && flags != cv::IMREAD_UNCHANGED) {
          ASSERT_EQ(expected.rows, 40);
        }
        ExpectSameImage(DecodeJpeg(jpeg, "a.jpg", flags), expected,
                        "orientation " + std::to_string(orientation) + (little_endian ? " II" : " MM") + ", flags " +
                            std::to_string(flags));
      }
    }
  }
}

// Where the entropy-coded data of the first scan starts and ends (its EOI marker).
std::pair<size_t, size_t> ScanData(const std::string& jpeg) {
  const size_t sos = jpeg.find("\xff\xda");
  const size_t length = (size_t{static_cast<unsigned char>(jpeg[sos + 2])} << 8) | static_cast<unsigned char>(jpeg[sos + 3]);
  return {sos + 2 + length, jpeg.rfind("\xff\xd9")};
}

// Issue 17: a JPEG whose markers are intact but whose entropy-coded data is damaged passed
// ReadImageFile's structure check, and libjpeg printed "Corrupt JPEG data: bad Huffman code",
// "premature end of data segment" or "N extraneous bytes before marker 0xd9" (fuzz_image met
// them every run) while OpenCV returned the damaged picture. Bytes flipped at 40 places inside
// the scan: where libjpeg warned through cv::imdecode, ReadImageFile is one error naming the
// file and quoting libjpeg; where libjpeg saw nothing (JPEG has no checksum), it returns what
// imdecode returns. Neither prints anything.
TEST(ReadImageFile, DamagedEntropyCodedDataIsOneErrorNamingTheFileAndLibjpegSaysNothing) {
  const fs::path file = fs::path(::testing::TempDir()) / ("arview_entropy_" + std::to_string(::getpid()) + ".jpg");
  const std::string whole = Encode(Picture(64, 48));
  const auto [begin, end] = ScanData(whole);
  int warned = 0;
  for (int i = 0; i < 40; ++i) {
    const size_t at = begin + (end - begin) * i / 40;
    std::string damaged = whole;
    // Keep the marker structure: no 0xFF made or unmade, the byte after an 0xFF left alone.
    if (damaged[at] == '\xff' || damaged[at - 1] == '\xff' || (damaged[at] ^ 0x5a) == '\xff') continue;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << damaged;
    const auto [expected, libjpeg_said] = Imdecode(damaged, cv::IMREAD_COLOR);
    ::testing::internal::CaptureStderr();
    try {
      const cv::Mat image = ReadImageFile(file, cv::IMREAD_COLOR);
      EXPECT_EQ(libjpeg_said, "") << "read although libjpeg warned, byte " << at;
      ExpectSameImage(image, expected, "byte " + std::to_string(at));
    } catch (const Error& e) {
      ++warned;
      EXPECT_NE(libjpeg_said, "") << "refused although libjpeg saw nothing, byte " << at << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": damaged JPEG data (libjpeg: ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "byte " << at;
  }
  EXPECT_GE(warned, 10) << "too few of the flips were damage libjpeg notices: the test no longer tests it";
  fs::remove(file);
}

// Bytes between the end of the scan and EOI ("Corrupt JPEG data: 14 extraneous bytes before
// marker 0xd9"): refused in a file; a live MJPEG frame (webcams pad so) is whole and kept.
TEST(DecodeJpeg, PaddingBeforeEoiIsRefusedInFilesAndAcceptedInMjpegFrames) {
  const std::string whole = Encode(Picture(32, 24));
  const size_t eoi = whole.rfind("\xff\xd9");
  const std::string padded = whole.substr(0, eoi) + std::string(16, '\0') + whole.substr(eoi);
  ASSERT_NE(Imdecode(padded, cv::IMREAD_COLOR).second.find("extraneous bytes before marker 0xd9"), std::string::npos);
  ::testing::internal::CaptureStderr();
  try {
    (void)DecodeImageBytes(padded, "padded.jpg", cv::IMREAD_COLOR);
    ADD_FAILURE() << "a padded JPEG file was read";
  } catch (const Error& e) {
    // libjpeg-turbo counts the bytes its Huffman decoder has not already fetched (up to 16).
    // (No std::regex: gcc's -Wmaybe-uninitialized misfires inside it in the asan build.)
    const std::string message = e.what();
    const std::string head = "padded.jpg: damaged JPEG data (libjpeg: Corrupt JPEG data: ";
    const std::string tail = " extraneous bytes before marker 0xd9)";
    ASSERT_TRUE(message.starts_with(head) && message.ends_with(tail)) << message;
    const std::string count = message.substr(head.size(), message.size() - head.size() - tail.size());
    EXPECT_TRUE(!count.empty() && count.find_first_not_of("0123456789") == std::string::npos) << message;
  }
  const cv::Mat frame = DecodeJpeg(padded, "MJPEG frame", cv::IMREAD_COLOR, JpegDamage::kAcceptPaddingBeforeEnd);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ExpectSameImage(frame, Imdecode(whole, cv::IMREAD_COLOR).first, "padded MJPEG frame");
  // Padding anywhere else is damage, even in a stream.
  const size_t dqt = whole.find("\xff\xdb");
  const std::string early = whole.substr(0, dqt) + std::string(2, '\0') + whole.substr(dqt);
  ::testing::internal::CaptureStderr();
  EXPECT_THROW(DecodeJpeg(early, "MJPEG frame", cv::IMREAD_COLOR, JpegDamage::kAcceptPaddingBeforeEnd), Error);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

// What libjpeg refuses outright (here a frame header of 16-bit precision, which libjpeg-turbo's
// 8-bit build cannot decode) is its error text after ours, nothing printed.
TEST(DecodeJpeg, WhatLibjpegRefusesIsOneErrorQuotingIt) {
  std::string jpeg = Encode(Picture(16, 16));
  jpeg[jpeg.find("\xff\xc0") + 4] = 16;
  ::testing::internal::CaptureStderr();
  try {
    (void)DecodeJpeg(jpeg, "deep.jpg", cv::IMREAD_COLOR);
    ADD_FAILURE() << "a 16-bit JPEG was decoded";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "deep.jpg: cannot be decoded as a JPEG (libjpeg: Unsupported JPEG data precision 16)");
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace arview
