// Speed of the per-frame work of live capture and recording, at 640x480: decoding the two
// V4L2 formats, writing one frame the way RecordingWriter does (PNG, compression 1), and the capture
// guidance record adds to each frame; and of
// reading one of phone-fox's 1920x1080 JPEG frames, through ReadImageFile (the checks and the
// decoder replay uses) and through cv::imdecode alone (what it is measured against); and the
// same for templeRing's 640x480 PNG photos, all of them each iteration.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/image_file.h"
#include "base/png_decoder.h"
#include "recordings/capture_guidance.h"
#include "recordings/recorder.h"
#include "recordings/v4l2_source.h"
#include "tests/support/test_data.h"

namespace {

using namespace arview::recordings;

// A camera-like 640x480 image: smooth shading plus texture, so that codecs work realistically.
cv::Mat Scene() {
  cv::Mat image(480, 640, CV_8UC3);
  cv::RNG rng(1);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(x / 3), static_cast<uchar>(y / 2), 120);
    }
  }
  for (int i = 0; i < 300; ++i) {
    cv::circle(image, {rng.uniform(0, 640), rng.uniform(0, 480)}, rng.uniform(2, 30),
               cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256)), -1);
  }
  return image;
}

void BM_DecodeYuyv640x480(benchmark::State& state) {
  cv::Mat yuv;
  cv::cvtColor(Scene(), yuv, cv::COLOR_BGR2YUV);
  std::vector<uint8_t> packed(640 * 480 * 2);
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const cv::Vec3b p = yuv.at<cv::Vec3b>(y, x);
      packed[(y * 640 + x) * 2] = p[0];
      packed[(y * 640 + x) * 2 + 1] = x % 2 ? p[2] : p[1];
    }
  }
  for (auto _ : state) benchmark::DoNotOptimize(DecodeYuyv(packed.data(), packed.size(), 640, 480, 1280));
}
BENCHMARK(BM_DecodeYuyv640x480)->Unit(benchmark::kMillisecond);

void BM_DecodeMjpeg640x480(benchmark::State& state) {
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", Scene(), jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
  for (auto _ : state) benchmark::DoNotOptimize(DecodeMjpeg(jpeg.data(), jpeg.size(), 640, 480));
  state.counters["jpeg_bytes"] = static_cast<double>(jpeg.size());
}
BENCHMARK(BM_DecodeMjpeg640x480)->Unit(benchmark::kMillisecond);

void BM_RecordFrame640x480(benchmark::State& state) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("arview_bench_record_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const cv::Mat image = Scene();
  {
    RecordingWriter writer(dir, std::nullopt, false);
    double t = 0;
    for (auto _ : state) writer.Append(image, t += 1.0 / 30);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_RecordFrame640x480)->Unit(benchmark::kMillisecond);

// The capture guidance `record` adds to each frame (recordings/capture_guidance.h): the scene
// sliding 4 px a frame, so that points are followed and views kept as a walking camera's are.
void BM_CaptureGuidance640x480(benchmark::State& state) {
  cv::Mat wide;
  cv::hconcat(std::vector<cv::Mat>(4, Scene()), wide);
  CaptureGuidance guidance;
  int i = 0;
  for (auto _ : state) {
    const int x = (4 * i) % (wide.cols - 640);
    guidance.Add(wide(cv::Rect(x, 0, 640, 480)), i++ / 30.0);
  }
}
BENCHMARK(BM_CaptureGuidance640x480)->Unit(benchmark::kMillisecond);

// phone-fox's first frame (1920x1080, 4:2:0, 387 KB), or empty when ../shared/data is absent.
std::filesystem::path PhoneFoxFrame() {
  const std::filesystem::path frame = arview::testing::SharedData("phone-fox/images/0001.jpg");
  return std::filesystem::is_regular_file(frame) ? frame : std::filesystem::path();
}

void BM_ReadImageFilePhoneFoxFrame(benchmark::State& state) {
  const std::filesystem::path frame = PhoneFoxFrame();
  if (frame.empty()) return state.SkipWithError("phone-fox/images/0001.jpg missing (../shared/data)");
  for (auto _ : state) benchmark::DoNotOptimize(arview::ReadImageFile(frame, cv::IMREAD_COLOR));
}
BENCHMARK(BM_ReadImageFilePhoneFoxFrame)->Unit(benchmark::kMillisecond);

void BM_ImdecodePhoneFoxFrame(benchmark::State& state) {
  const std::filesystem::path frame = PhoneFoxFrame();
  if (frame.empty()) return state.SkipWithError("phone-fox/images/0001.jpg missing (../shared/data)");
  std::ifstream in(frame, std::ios::binary);
  const std::vector<uchar> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  for (auto _ : state) benchmark::DoNotOptimize(cv::imdecode(bytes, cv::IMREAD_COLOR));
}
BENCHMARK(BM_ImdecodePhoneFoxFrame)->Unit(benchmark::kMillisecond);

// templeRing's PNG photos (640x480 RGB, 47 files), or none when ../shared/data is absent.
std::vector<std::filesystem::path> TempleRingPhotos() {
  std::vector<std::filesystem::path> photos;
  const std::filesystem::path folder = arview::testing::SharedData("templeRing");
  if (!std::filesystem::is_directory(folder)) return photos;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".png") photos.push_back(entry.path());
  }
  return photos;
}

std::vector<std::vector<uchar>> TempleRingBytes() {
  std::vector<std::vector<uchar>> all;
  for (const auto& photo : TempleRingPhotos()) {
    std::ifstream in(photo, std::ios::binary);
    all.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return all;
}

void BM_ReadImageFileTempleRing(benchmark::State& state) {
  const auto photos = TempleRingPhotos();
  if (photos.empty()) return state.SkipWithError("templeRing missing (../shared/data)");
  for (auto _ : state) {
    for (const auto& photo : photos) benchmark::DoNotOptimize(arview::ReadImageFile(photo, cv::IMREAD_COLOR));
  }
  state.counters["photos"] = static_cast<double>(photos.size());
}
BENCHMARK(BM_ReadImageFileTempleRing)->Unit(benchmark::kMillisecond);

void BM_DecodePngTempleRing(benchmark::State& state) {
  const auto all = TempleRingBytes();
  if (all.empty()) return state.SkipWithError("templeRing missing (../shared/data)");
  for (auto _ : state) {
    for (const auto& bytes : all) {
      benchmark::DoNotOptimize(arview::DecodePng(
          std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "photo", cv::IMREAD_COLOR));
    }
  }
}
BENCHMARK(BM_DecodePngTempleRing)->Unit(benchmark::kMillisecond);

void BM_ImdecodeTempleRing(benchmark::State& state) {
  const auto all = TempleRingBytes();
  if (all.empty()) return state.SkipWithError("templeRing missing (../shared/data)");
  for (auto _ : state) {
    for (const auto& bytes : all) benchmark::DoNotOptimize(cv::imdecode(bytes, cv::IMREAD_COLOR));
  }
}
BENCHMARK(BM_ImdecodeTempleRing)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
