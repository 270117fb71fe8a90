#include "recordings/importers.h"

#include <fstream>
#include <sstream>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "recordings/recording.h"
#include "tests/support/test_data.h"

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder under the system temp directory, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() / ("arview_recordings_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct ParLine {
  std::string name;
  Eigen::Matrix<double, 3, 4> P;
};

std::vector<ParLine> ReadProjections(const fs::path& par) {
  std::ifstream in(par);
  std::vector<ParLine> out;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    ParLine p;
    double v[21];
    ss >> p.name;
    for (double& x : v) ss >> x;
    if (!ss) continue;
    const Eigen::Matrix3d K = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v);
    const Eigen::Matrix3d R = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v + 9);
    Eigen::Matrix<double, 3, 4> Rt;
    Rt << R, Eigen::Vector3d(v[18], v[19], v[20]);
    p.P = K * Rt;
    out.push_back(p);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return out;
}

TEST(ImportMiddlebury, TempleRingMatchesTheOriginalProjections) {
  const fs::path src = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(src, "../shared/data");
  TempDir out("middlebury");
  const ImportResult result = ImportMiddlebury(src, out.path() / "temple");
  EXPECT_EQ(result.frame_count, 47);
  ASSERT_TRUE(result.has_groundtruth);

  const Recording rec = LoadRecording(out.path() / "temple");
  ASSERT_EQ(rec.frames.size(), 47u);
  ASSERT_TRUE(rec.groundtruth.has_value());
  ASSERT_EQ(rec.groundtruth->size(), 47u);
  EXPECT_EQ(rec.camera.width, 640);
  EXPECT_EQ(rec.camera.height, 480);
  EXPECT_EQ(rec.frames[0].path, "frames/000000.png");
  EXPECT_EQ(rec.frames[46].path, "frames/000046.png");
  EXPECT_FALSE(rec.IsVideo());
  EXPECT_EQ(rec.ReadImage(46).size(), cv::Size(640, 480));

  const std::vector<ParLine> original = ReadProjections(src / "templeR_par.txt");
  ASSERT_EQ(original.size(), 47u);
  // Points spread over the model's bounding box (README.txt) and beyond.
  const Eigen::Vector3d lo(-0.023121, -0.038009, -0.091940), hi(0.078626, 0.121636, -0.017395);
  double worst_px = 0, worst_center = 0;
  for (size_t i = 0; i < 47; ++i) {
    const StampedPose& gt = (*rec.groundtruth)[i];
    EXPECT_DOUBLE_EQ(gt.timestamp, static_cast<double>(i));
    const Eigen::Vector3d C = gt.pose.Center();
    // The camera centre is the right null space of the original P.
    worst_center = std::max(worst_center, (original[i].P * C.homogeneous()).norm() / original[i].P.norm());
    for (int k = 0; k < 27; ++k) {
      const Eigen::Vector3d f(k % 3 / 2.0, k / 3 % 3 / 2.0, k / 9 / 2.0);
      const Eigen::Vector3d X = lo + f.cwiseProduct(hi - lo) * 1.5 - 0.25 * (hi - lo);
      const Eigen::Vector3d x = original[i].P * X.homogeneous();
      const Eigen::Vector2d expected = x.head<2>() / x.z();
      const Eigen::Vector2d got = rec.camera.Project(gt.pose.ToCamera(X));
      worst_px = std::max(worst_px, (got - expected).norm());
    }
  }
  EXPECT_LT(worst_px, 1e-3) << "pixels";
  EXPECT_LT(worst_center, 1e-9);
  // The frames are the original files, copied in name order.
  const cv::Mat a = cv::imread((src / "templeR0001.png").string());
  const cv::Mat b = rec.ReadImage(0);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
}

void WriteFile(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

void WriteImage(const fs::path& p, int w, int h, int seed) {
  fs::create_directories(p.parent_path());
  cv::Mat image(h, w, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::putText(image, std::to_string(seed), {5, h / 2}, cv::FONT_HERSHEY_SIMPLEX, 1.0, {255, 255, 255}, 2);
  ASSERT_TRUE(cv::imwrite(p.string(), image));
}

const char* kPar2 =
    "2\n"
    "a.png 100 0 16 0 100 12 0 0 1  1 0 0 0 1 0 0 0 1  0 0 1\n"
    "b.png 100 0 16 0 100 12 0 0 1  0 -1 0 1 0 0 0 0 1  0.5 0 1\n";

TEST(ImportMiddlebury, RejectsIntrinsicsThatVaryBetweenImages) {
  TempDir dir("middlebury_k");
  WriteImage(dir.path() / "src/a.png", 32, 24, 1);
  WriteImage(dir.path() / "src/b.png", 32, 24, 2);
  WriteFile(dir.path() / "src/x_par.txt",
            "2\n"
            "a.png 100 0 16 0 100 12 0 0 1  1 0 0 0 1 0 0 0 1  0 0 1\n"
            "b.png 110 0 16 0 100 12 0 0 1  1 0 0 0 1 0 0 0 1  0 0 1\n");
  try {
    ImportMiddlebury(dir.path() / "src", dir.path() / "out");
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("x_par.txt:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("differs"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "out/frames.txt"));
}

TEST(ImportMiddlebury, ReportsMalformedLinesWithFileAndLine) {
  TempDir dir("middlebury_bad");
  WriteImage(dir.path() / "src/a.png", 32, 24, 1);
  WriteFile(dir.path() / "src/x_par.txt", "1\na.png 100 0 16 0 100 12 0 0 1 1 0 0 0 1 0 0 0 1 0 zero 1\n");
  try {
    ImportMiddlebury(dir.path() / "src", dir.path() / "out");
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("x_par.txt:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ImportMiddlebury(dir.path() / "nowhere", dir.path() / "out"), RecordingError);
}

TEST(ImportMiddlebury, RefusesToOverwriteWithoutPermission) {
  TempDir dir("middlebury_over");
  WriteImage(dir.path() / "src/a.png", 32, 24, 1);
  WriteImage(dir.path() / "src/b.png", 32, 24, 2);
  WriteFile(dir.path() / "src/x_par.txt", kPar2);
  ImportMiddlebury(dir.path() / "src", dir.path() / "out");
  EXPECT_THROW(ImportMiddlebury(dir.path() / "src", dir.path() / "out"), RecordingError);
  ImportOptions force;
  force.overwrite = true;
  EXPECT_EQ(ImportMiddlebury(dir.path() / "src", dir.path() / "out", force).frame_count, 2);
  // A folder that is not a recording is never replaced.
  WriteFile(dir.path() / "precious/notes.txt", "keep me");
  EXPECT_THROW(ImportMiddlebury(dir.path() / "src", dir.path() / "precious", force), RecordingError);
  EXPECT_TRUE(fs::exists(dir.path() / "precious/notes.txt"));
}

}  // namespace
}  // namespace arview::recordings
