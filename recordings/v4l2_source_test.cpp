#include "recordings/v4l2_source.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recordings/test_helpers.h"

namespace arview::recordings {
namespace {

std::string OpenError(const std::string& device) {
  try {
    V4l2Source source(device);
    return "";
  } catch (const SourceError& e) {
    return e.what();
  }
}

TEST(V4l2Source, AMissingDeviceIsNamedInOneMessage) {
  const std::string msg = OpenError("/dev/arview-no-such-camera");
  EXPECT_NE(msg.find("/dev/arview-no-such-camera: no such device"), std::string::npos) << msg;
}

TEST(V4l2Source, DevNullIsNotAVideoDevice) {
  const std::string msg = OpenError("/dev/null");
  EXPECT_NE(msg.find("/dev/null: not a V4L2 video device"), std::string::npos) << msg;
}

TEST(V4l2Source, ARegularFileIsNotAVideoDevice) {
  test::TempDir dir("v4l2");
  test::WriteFile(dir.path() / "video0", "not a device");
  const std::string msg = OpenError((dir.path() / "video0").string());
  EXPECT_NE(msg.find("not a video device"), std::string::npos) << msg;
}

TEST(V4l2Source, BadOptionsAreRejectedBeforeOpening) {
  V4l2Options options;
  options.format = "h264";
  EXPECT_THROW(V4l2Source("/dev/null", options), SourceError);
  options = {};
  options.width = 0;
  EXPECT_THROW(V4l2Source("/dev/null", options), SourceError);
}

using test::PackYuyv;

TEST(DecodeYuyv, RecoversTheColoursOfAStoredBuffer) {
  // Flat 2-pixel-wide colour bars: chroma subsampling loses nothing, so only rounding remains.
  cv::Mat bgr(8, 16, CV_8UC3);
  const cv::Vec3b colours[] = {{255, 255, 255}, {0, 0, 0}, {0, 0, 255}, {0, 255, 0},
                               {255, 0, 0},     {40, 90, 200}, {128, 128, 128}, {200, 30, 60}};
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) bgr.at<cv::Vec3b>(y, x) = colours[(x / 2 + y) % 8];
  }
  const std::vector<uint8_t> packed = PackYuyv(bgr, 6);
  const cv::Mat decoded = DecodeYuyv(packed.data(), packed.size(), 16, 8, 2 * 16 + 6);
  ASSERT_EQ(decoded.size(), bgr.size());
  ASSERT_EQ(decoded.type(), CV_8UC3);
  EXPECT_LE(cv::norm(decoded, bgr, cv::NORM_INF), 3);
}

TEST(DecodeYuyv, RejectsShortBuffersAndOddWidths) {
  std::vector<uint8_t> data(2 * 16 * 8 - 1);
  EXPECT_THROW(DecodeYuyv(data.data(), data.size(), 16, 8, 32), SourceError);
  data.resize(2 * 16 * 8);
  EXPECT_NO_THROW(DecodeYuyv(data.data(), data.size(), 16, 8, 32));
  EXPECT_THROW(DecodeYuyv(data.data(), data.size(), 15, 8, 32), SourceError);
  EXPECT_THROW(DecodeYuyv(data.data(), data.size(), 16, 8, 30), SourceError);
  EXPECT_THROW(DecodeYuyv(nullptr, 0, 16, 8, 32), SourceError);
}

// Removes every DHT (Huffman table) segment before the first scan, as many UVC cameras send.
std::vector<uint8_t> StripHuffmanTables(const std::vector<uint8_t>& jpeg) {
  std::vector<uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
  size_t i = 2;
  while (jpeg[i + 1] != 0xDA) {
    const size_t len = (size_t{jpeg[i + 2]} << 8) | jpeg[i + 3];
    if (jpeg[i + 1] != 0xC4) out.insert(out.end(), jpeg.begin() + i, jpeg.begin() + i + 2 + len);
    i += 2 + len;
  }
  out.insert(out.end(), jpeg.begin() + i, jpeg.end());
  return out;
}

TEST(DecodeMjpeg, DecodesFramesWithAndWithoutHuffmanTables) {
  const cv::Mat bgr = test::MakeImage(64, 48, 3);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  const cv::Mat reference = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  const cv::Mat full = DecodeMjpeg(jpeg.data(), jpeg.size(), 64, 48);
  EXPECT_EQ(cv::norm(full, reference, cv::NORM_INF), 0);

  const std::vector<uint8_t> bare = StripHuffmanTables(jpeg);
  ASSERT_LT(bare.size(), jpeg.size());
  const cv::Mat restored = DecodeMjpeg(bare.data(), bare.size(), 64, 48);
  EXPECT_EQ(cv::norm(restored, reference, cv::NORM_INF), 0);
}

TEST(DecodeMjpeg, RejectsCorruptDataAndWrongSizes) {
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", test::MakeImage(64, 48, 1), jpeg));
  EXPECT_THROW(DecodeMjpeg(jpeg.data(), jpeg.size(), 640, 480), SourceError);
  const std::vector<uint8_t> garbage = {0x00, 0x11, 0x22, 0x33, 0x44};
  EXPECT_THROW(DecodeMjpeg(garbage.data(), garbage.size()), SourceError);
  const std::vector<uint8_t> truncated(jpeg.begin(), jpeg.begin() + 40);
  EXPECT_THROW(DecodeMjpeg(truncated.data(), truncated.size()), SourceError);
  EXPECT_THROW(DecodeMjpeg(nullptr, 0), SourceError);
}

// A frame cut short by a USB hiccup was decoded by cv::imdecode with its missing part grey and
// not a word; a frame with flipped bits in its data made libjpeg print "Corrupt JPEG data: ..."
// on stderr. Both are now skipped as corrupt frames, libjpeg printing nothing; zeros before EOI
// (webcams pad frames so) still decode to the frame.
TEST(DecodeMjpeg, CutOrDamagedFramesAreRefusedSilentlyAndPaddedOnesKept) {
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", test::MakeImage(64, 48, 3), jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  const cv::Mat reference = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  const std::vector<uint8_t> cut(jpeg.begin(), jpeg.begin() + static_cast<long>(jpeg.size() * 2 / 3));
  std::vector<uint8_t> padded = jpeg;
  padded.insert(padded.end() - 2, 16, 0);
  ::testing::internal::CaptureStderr();
  try {
    (void)DecodeMjpeg(cut.data(), cut.size(), 64, 48);
    ADD_FAILURE() << "a cut frame was decoded";
  } catch (const SourceError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("MJPEG frame: damaged JPEG data (libjpeg: ", 0), 0u) << e.what();
  }
  const cv::Mat kept = DecodeMjpeg(padded.data(), padded.size(), 64, 48);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(cv::norm(kept, reference, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace arview::recordings
