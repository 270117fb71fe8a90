#pragma once
// Helpers shared by the recordings/ unit tests (header only; not part of the library).

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace arview::recordings::test {

// A fresh, empty folder under the system temp directory, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("arview_recordings_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void WriteFile(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// A smooth image with a disc whose place and colour depend on `seed`: distinct per frame,
// deterministic, and smooth enough to survive lossy video compression recognisably.
inline cv::Mat MakeImage(int w, int h, int seed) {
  cv::Mat image(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(4 * x), static_cast<uchar>(5 * y), 90);
    }
  }
  const cv::Point centre(8 + (seed * 13) % std::max(1, w - 16), 8 + (seed * 7) % std::max(1, h - 16));
  cv::circle(image, centre, std::min(w, h) / 5, cv::Scalar(255 - 20 * (seed % 8), 255, 30 * (seed % 8)), -1);
  return image;
}

inline void WriteImage(const std::filesystem::path& p, int w, int h, int seed) {
  std::filesystem::create_directories(p.parent_path());
  ASSERT_TRUE(cv::imwrite(p.string(), MakeImage(w, h, seed)));
}

// Writes a short 64x48 MJPEG AVI of MakeImage(64, 48, i) frames with OpenCV's FFmpeg backend.
inline bool WriteTestVideo(const std::filesystem::path& file, int frames, double fps) {
  cv::VideoWriter writer(file.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                         cv::Size(64, 48));
  if (!writer.isOpened()) return false;
  for (int i = 0; i < frames; ++i) writer.write(MakeImage(64, 48, i));
  return true;
}

// Packs a BGR image into YUYV the way a camera does (BT.601 video range, chroma averaged over
// each horizontal pixel pair), with `pad` spare bytes at the end of each row.
inline std::vector<uint8_t> PackYuyv(const cv::Mat& bgr, int pad) {
  const int stride = 2 * bgr.cols + pad;
  std::vector<uint8_t> out(static_cast<size_t>(stride) * bgr.rows, 0xEE);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; x += 2) {
      double u = 0, v = 0;
      for (int k = 0; k < 2; ++k) {
        const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x + k);
        const double b = p[0], g = p[1], r = p[2];
        const double Y = 16 + 0.257 * r + 0.504 * g + 0.098 * b;
        u += 0.5 * (128 - 0.148 * r - 0.291 * g + 0.439 * b);
        v += 0.5 * (128 + 0.439 * r - 0.368 * g - 0.071 * b);
        out[static_cast<size_t>(y) * stride + 2 * (x + k)] = cv::saturate_cast<uint8_t>(Y);
      }
      out[static_cast<size_t>(y) * stride + 2 * x + 1] = cv::saturate_cast<uint8_t>(u);
      out[static_cast<size_t>(y) * stride + 2 * x + 3] = cv::saturate_cast<uint8_t>(v);
    }
  }
  return out;
}

}  // namespace arview::recordings::test
