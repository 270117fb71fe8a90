#include "recordings/importers.h"

#include <fstream>
#include <iterator>
#include <iostream>
#include <sstream>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "recordings/recording.h"
#include "recordings/test_helpers.h"
#include "tests/support/test_data.h"

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;

using test::TempDir;
using test::WriteFile;
using test::WriteImage;

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
  std::cout << "[ measured ] templeRing: worst reprojection difference " << worst_px
            << " px, worst |P C| / |P| " << worst_center << "\n";
  EXPECT_LT(worst_px, 1e-3) << "pixels";
  EXPECT_LT(worst_center, 1e-9);
  // The frames are the original files, copied in name order.
  const cv::Mat a = cv::imread((src / "templeR0001.png").string());
  const cv::Mat b = rec.ReadImage(0);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
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

// ---------------------------------------------------------------- Strecha

// K[Rᵀ | −RᵀC] as the EPFL benchmark defines it.
Eigen::Matrix<double, 3, 4> StrechaP(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& C) {
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << R_wc.transpose(), -R_wc.transpose() * C;
  return K * Rt;
}

std::string StrechaFile(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& C,
                        const std::string& distortion = "0 0 0") {
  std::ostringstream o;
  o.precision(17);
  for (int r = 0; r < 3; ++r) o << K(r, 0) << " " << K(r, 1) << " " << K(r, 2) << "\n";
  o << distortion << "\n";
  for (int r = 0; r < 3; ++r) o << R_wc(r, 0) << " " << R_wc(r, 1) << " " << R_wc(r, 2) << "\n";
  o << C.x() << " " << C.y() << " " << C.z() << "\n";
  o << "64 48\n";
  return o.str();
}

TEST(ImportStrecha, GroundTruthReprojectsLikeTheBenchmarkCameras) {
  TempDir dir("strecha");
  Eigen::Matrix3d K;
  K << 70, 0, 31.5, 0, 71, 23.5, 0, 0, 1;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < 3; ++i) {
    rotations.push_back(Eigen::AngleAxisd(0.3 * i + 0.1, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix());
    centres.emplace_back(i * 0.5, -0.2 * i, 1.0 + i);
    const std::string name = "000" + std::to_string(i) + (i == 1 ? ".jpg" : ".png");
    WriteImage(dir.path() / "src/images" / name, 64, 48, i);
    WriteFile(dir.path() / "src/gt_dense_cameras" / (name + ".camera"), StrechaFile(K, rotations[i], centres[i]));
  }
  const ImportResult result = ImportStrecha(dir.path() / "src", dir.path() / "out");
  EXPECT_EQ(result.frame_count, 3);
  const Recording rec = LoadRecording(dir.path() / "out");
  ASSERT_TRUE(rec.groundtruth);
  ASSERT_EQ(rec.groundtruth->size(), 3u);
  EXPECT_DOUBLE_EQ(rec.camera.fx, 70);
  EXPECT_DOUBLE_EQ(rec.camera.cy, 23.5);
  for (int i = 0; i < 3; ++i) {
    const calib::Pose& pose = (*rec.groundtruth)[i].pose;
    EXPECT_LT((pose.Center() - centres[i]).norm(), 1e-12);
    const Eigen::Vector3d X(0.3, -0.1, 5.0);
    const Eigen::Vector3d x = StrechaP(K, rotations[i], centres[i]) * X.homogeneous();
    EXPECT_LT((rec.camera.Project(pose.ToCamera(X)) - x.head<2>() / x.z()).norm(), 1e-9);
    EXPECT_EQ(rec.ReadImage(i).size(), cv::Size(64, 48));
  }
  EXPECT_EQ(rec.frames[1].path, "frames/000001.png");  // the JPEG became a PNG
}

TEST(ImportStrecha, ReportsBadCameraFilesWithFileAndLine) {
  TempDir dir("strecha_bad");
  Eigen::Matrix3d K;
  K << 70, 0, 31.5, 0, 71, 23.5, 0, 0, 1;
  WriteImage(dir.path() / "src/images/0000.png", 64, 48, 0);
  std::string text = StrechaFile(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  text.replace(text.find("0 0 0\n"), 6, "0 0\n");
  WriteFile(dir.path() / "src/gt_dense_cameras/0000.png.camera", text);
  try {
    ImportStrecha(dir.path() / "src", dir.path() / "out");
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("0000.png.camera:4"), std::string::npos) << e.what();
  }
  WriteFile(dir.path() / "src/gt_dense_cameras/0000.png.camera",
            StrechaFile(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), "0.1 0 0"));
  EXPECT_THROW(ImportStrecha(dir.path() / "src", dir.path() / "out"), RecordingError);
  fs::remove(dir.path() / "src/gt_dense_cameras/0000.png.camera");
  try {
    ImportStrecha(dir.path() / "src", dir.path() / "out");
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("0000.png.camera"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------- TUM, images, video

calib::Camera SmallCamera() { return calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5); }

TEST(ImportTum, KeepsTimestampsAndCopiesGroundTruth) {
  TempDir dir("tum");
  const fs::path src = dir.path() / "rgbd_dataset_test";
  WriteFile(src / "rgb.txt",
            "# color images\n# file: 'test.bag'\n# timestamp filename\n"
            "1305031102.175304 rgb/1305031102.175304.png\n"
            "1305031102.211214 rgb/1305031102.211214.png\n"
            "1305031102.243211 rgb/1305031102.243211.png\n");
  for (const char* t : {"1305031102.175304", "1305031102.211214", "1305031102.243211"}) {
    WriteImage(src / "rgb" / (std::string(t) + ".png"), 64, 48, 1);
  }
  WriteFile(src / "groundtruth.txt",
            "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
            "1305031102.1758 1.3405 0.6266 1.6575 0.6574 0.6126 -0.2949 -0.3248\n"
            "1305031102.1858 1.3303 0.6256 1.6464 0.6579 0.6161 -0.2932 -0.3189\n"
            "1305031102.2158 1.3160 0.6254 1.6302 0.6609 0.6199 -0.2893 -0.3086\n"
            "1305031102.2458 1.3054 0.6251 1.6161 0.6641 0.6236 -0.2850 -0.2969\n");
  EXPECT_THROW(ImportTum(src, dir.path() / "out"), RecordingError);  // no intrinsics anywhere
  ImportOptions options;
  options.camera = SmallCamera();
  const ImportResult result = ImportTum(src, dir.path() / "out", options);
  EXPECT_EQ(result.frame_count, 3);
  EXPECT_TRUE(result.has_groundtruth);
  const Recording rec = LoadRecording(dir.path() / "out");
  ASSERT_EQ(rec.frames.size(), 3u);
  EXPECT_NEAR(rec.frames[1].timestamp, 1305031102.211214, 1e-6);
  ASSERT_TRUE(rec.groundtruth);
  ASSERT_EQ(rec.groundtruth->size(), 4u);
  EXPECT_NEAR((*rec.groundtruth)[2].pose.Center().x(), 1.3160, 1e-12);
  // A missing image is named.
  fs::remove(src / "rgb/1305031102.211214.png");
  options.overwrite = true;
  try {
    ImportTum(src, dir.path() / "out", options);
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("1305031102.211214.png"), std::string::npos) << e.what();
  }
}

TEST(ImportImages, TakesImagesInNameOrderWithTheGivenCamera) {
  TempDir dir("images");
  WriteImage(dir.path() / "src/b.jpg", 64, 48, 2);
  WriteImage(dir.path() / "src/a.png", 64, 48, 1);
  WriteImage(dir.path() / "src/c.bmp", 64, 48, 3);
  WriteFile(dir.path() / "src/notes.txt", "not an image");
  ImportOptions options;
  options.camera = SmallCamera();
  EXPECT_EQ(ImportImages(dir.path() / "src", dir.path() / "out", options).frame_count, 3);
  const Recording rec = LoadRecording(dir.path() / "out");
  ASSERT_EQ(rec.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(rec.frames[2].timestamp, 2.0);
  EXPECT_FALSE(rec.groundtruth);
  EXPECT_EQ(cv::norm(rec.ReadImage(0), cv::imread((dir.path() / "src/a.png").string()), cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(rec.ReadImage(2), cv::imread((dir.path() / "src/c.bmp").string()), cv::NORM_INF), 0);
  // An image of another size than the camera is an error naming it.
  WriteImage(dir.path() / "src/d.png", 32, 48, 4);
  options.overwrite = true;
  try {
    ImportImages(dir.path() / "src", dir.path() / "out", options);
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("d.png"), std::string::npos) << e.what();
  }
}

// Issue 17 §6: an import that failed part-way (a damaged source image, a full disk) left the
// frames it had copied (on a full disk a 0-byte frames/000000.png) in a folder without frames.txt.
TEST(ImportImages, AnImportThatFailsPartWayLeavesNothingBehind) {
  TempDir dir("images_fail");
  WriteImage(dir.path() / "src/a.png", 64, 48, 1);
  WriteImage(dir.path() / "src/b.jpg", 64, 48, 2);
  WriteImage(dir.path() / "src/c.png", 64, 48, 3);
  std::ifstream in(dir.path() / "src/c.png", std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  in.close();
  WriteFile(dir.path() / "src/c.png", bytes.substr(0, bytes.size() / 2));  // cut: the third frame fails
  ImportOptions options;
  options.camera = SmallCamera();
  // Into a folder the import creates: the folder goes too.
  EXPECT_THROW(ImportImages(dir.path() / "src", dir.path() / "new", options), RecordingError);
  EXPECT_FALSE(fs::exists(dir.path() / "new"));
  // Into an empty folder the user made: it stays, empty.
  fs::create_directories(dir.path() / "empty");
  EXPECT_THROW(ImportImages(dir.path() / "src", dir.path() / "empty", options), RecordingError);
  EXPECT_TRUE(fs::is_directory(dir.path() / "empty"));
  EXPECT_TRUE(fs::is_empty(dir.path() / "empty"));
  // A folder that is not a recording is refused before anything is touched, its files kept.
  WriteFile(dir.path() / "mine/frames/keep.png", "the user's");
  EXPECT_THROW(ImportImages(dir.path() / "src", dir.path() / "mine", options), RecordingError);
  EXPECT_TRUE(fs::exists(dir.path() / "mine/frames/keep.png"));
}

using test::WriteTestVideo;

TEST(ImportVideo, CountsFramesAndKeepsTheirTimestamps) {
  TempDir dir("video");
  ASSERT_TRUE(WriteTestVideo(dir.path() / "clip.avi", 12, 10.0));
  // No --camera: an estimated camera of the video's size, marked uncalibrated.
  ImportVideo(dir.path() / "clip.avi", dir.path() / "guessed");
  const Recording guessed = LoadRecording(dir.path() / "guessed");
  EXPECT_FALSE(guessed.camera.calibrated);
  EXPECT_DOUBLE_EQ(guessed.camera.fx, 0.6 * std::hypot(guessed.camera.width, guessed.camera.height));
  ImportOptions options;
  options.camera = SmallCamera();
  EXPECT_EQ(ImportVideo(dir.path() / "clip.avi", dir.path() / "out", options).frame_count, 12);
  const Recording rec = LoadRecording(dir.path() / "out");
  ASSERT_EQ(rec.frames.size(), 12u);
  EXPECT_TRUE(rec.IsVideo());
  EXPECT_EQ(rec.frames[0].path, "frames/clip.avi");
  for (size_t i = 0; i < rec.frames.size(); ++i) EXPECT_NEAR(rec.frames[i].timestamp, 0.1 * i, 1e-6);
  // Wrong camera size; not a video.
  options.camera = calib::Camera::Pinhole(640, 480, 500, 500, 320, 240);
  options.overwrite = true;
  EXPECT_THROW(ImportVideo(dir.path() / "clip.avi", dir.path() / "out", options), RecordingError);
  WriteFile(dir.path() / "fake.mp4", "this is not a video");
  EXPECT_THROW(ImportVideo(dir.path() / "fake.mp4", dir.path() / "out2", options), RecordingError);
  EXPECT_THROW(ImportVideo(dir.path() / "missing.mp4", dir.path() / "out2", options), RecordingError);
}

TEST(Import, DispatchesByKindAndRejectsUnknownKinds) {
  EXPECT_THROW(Import("colmap", "/tmp", "/tmp/none"), RecordingError);
  EXPECT_EQ(ImporterKinds().size(), 5u);
}

}  // namespace
}  // namespace arview::recordings
