#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "recordings/recording.h"
#include "room/ray_caster.h"
#include "room/room_light.h"
#include "figure/humanoid.h"
#include "synth/synth_room.h"
#include "render/test_scene.h"
#include "tests/support/test_data.h"

namespace arview::synth {
using namespace arview::room;  // the light estimated from the rendered room
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("arview_synth_test_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(counter++));
    fs::remove_all(path);
  }
  ~TempDir() { fs::remove_all(path); }
  static inline int counter = 0;
};

std::string Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(RoomPath, IsDeterministicForASeedAndDiffersBetweenSeeds) {
  const RoomPath a(10, 7), b(10, 7), c(10, 8);
  for (double t : {0.0, 3.3, 7.9}) {
    EXPECT_TRUE(a.At(t).t_cw.isApprox(b.At(t).t_cw, 0));
    EXPECT_TRUE(a.At(t).q_cw.coeffs().isApprox(b.At(t).q_cw.coeffs(), 0));
    EXPECT_GT((a.At(t).Center() - c.At(t).Center()).norm(), 1e-3);
  }
}

TEST(RoomPath, StaysInsideTheRoomAndMovesLikeAHandHeldCamera) {
  const RoomPath path(10, 1);
  const double dt = 1.0 / 30;
  double fastest_turn = 0;
  for (int i = 0; i < 300; ++i) {
    const calib::Pose p0 = path.At(i * dt), p1 = path.At((i + 1) * dt);
    const Eigen::Vector3d c = p0.Center();
    EXPECT_LT(std::abs(c.x()), 3.0);
    EXPECT_LT(std::abs(c.y()), 2.0);
    EXPECT_GT(c.z(), 1.2);
    EXPECT_LT((p1.Center() - c).norm(), 0.05) << "jump at frame " << i;  // < 1.5 m/s
    fastest_turn = std::max(fastest_turn, p0.q_cw.angularDistance(p1.q_cw) / dt);
  }
  // The fast turn: well over 150°/s at its peak, but not a teleport.
  EXPECT_GT(fastest_turn, 150 * M_PI / 180);
  EXPECT_LT(fastest_turn, 400 * M_PI / 180);
}

// Compares a rendered panel with its texture warped by the homography that the ground-truth
// pose gives for the panel's four 3D corners: the sub-pixel shift between the two must be ~0.
struct PanelCheck {
  bool usable = false;
  double ncc = 0;
  cv::Point2d shift;
};

PanelCheck CheckPanel(const cv::Mat& rendered_grey, const cv::Mat& texture, const RoomPanel& panel,
                      const calib::Camera& camera, const calib::Pose& pose) {
  PanelCheck check;
  std::vector<cv::Point2f> projected;
  for (const auto& corner : panel.corners) {
    const Eigen::Vector3d in_camera = pose.ToCamera(corner);
    if (in_camera.z() < 0.3) return check;
    const Eigen::Vector2d px = camera.Project(in_camera);
    if (!camera.InImage(px, 8)) return check;
    projected.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  std::vector<cv::Point> polygon(projected.begin(), projected.end());
  const double area = std::abs(cv::contourArea(projected));
  if (area < 80 * 80) return check;

  // Shrink the texture near the on-screen size first (INTER_AREA), as mipmapping does.
  const double scale = std::min(1.0, std::sqrt(area / (texture.cols * texture.rows)) * 1.2);
  cv::Mat small, grey;
  cv::resize(texture, small, {}, scale, scale, cv::INTER_AREA);
  cv::cvtColor(small, grey, cv::COLOR_BGR2GRAY);
  // Texture coordinates (0,0)-(1,1) span the texels' outer edges: OpenCV pixel −0.5 to N − 0.5.
  const float w = static_cast<float>(small.cols), h = static_cast<float>(small.rows);
  const std::vector<cv::Point2f> tex_corners = {{-0.5f, -0.5f}, {w - 0.5f, -0.5f}, {w - 0.5f, h - 0.5f}, {-0.5f, h - 0.5f}};
  cv::Mat expected;
  cv::warpPerspective(grey, expected, cv::getPerspectiveTransform(tex_corners, projected), rendered_grey.size(),
                      cv::INTER_LINEAR);

  cv::Mat mask = cv::Mat::zeros(rendered_grey.size(), CV_8U);
  cv::fillConvexPoly(mask, polygon, cv::Scalar(255));
  cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return check;
  cv::Mat a, b;
  rendered_grey(box).convertTo(a, CV_32F);
  expected(box).convertTo(b, CV_32F);
  const cv::Mat m = mask(box);
  // Outside the panel both images get their own mean, so the borders do not correlate.
  a.setTo(cv::mean(a, m), ~m);
  b.setTo(cv::mean(b, m), ~m);
  // Normalised cross-correlation of the expected panel (shrunk by kSearch) over the rendered
  // one at integer shifts, refined to sub-pixel by a parabola through the peak's neighbours.
  constexpr int kSearch = 3;
  if (a.cols <= 2 * kSearch + 16 || a.rows <= 2 * kSearch + 16) return check;
  const cv::Mat templ = b(cv::Rect(kSearch, kSearch, b.cols - 2 * kSearch, b.rows - 2 * kSearch));
  cv::Mat scores;
  cv::matchTemplate(a, templ, scores, cv::TM_CCOEFF_NORMED);
  cv::Point peak;
  cv::minMaxLoc(scores, nullptr, &check.ncc, nullptr, &peak);
  if (peak.x == 0 || peak.y == 0 || peak.x == scores.cols - 1 || peak.y == scores.rows - 1) return check;
  auto refine = [](float left, float centre, float right) {
    const double denominator = left - 2.0 * centre + right;
    return denominator < 0 ? 0.5 * (left - right) / denominator : 0.0;
  };
  check.shift.x = peak.x - kSearch + refine(scores.at<float>(peak.y, peak.x - 1), scores.at<float>(peak),
                                            scores.at<float>(peak.y, peak.x + 1));
  check.shift.y = peak.y - kSearch + refine(scores.at<float>(peak.y - 1, peak.x), scores.at<float>(peak),
                                            scores.at<float>(peak.y + 1, peak.x));
  check.usable = true;
  return check;
}

// Times along the paths of two seeds, every 0.4 s.
std::vector<std::pair<uint64_t, double>> Poses() {
  std::vector<std::pair<uint64_t, double>> poses;
  for (uint64_t seed : {1, 2})
    for (int i = 0; i < 25; ++i) poses.emplace_back(seed, 0.4 * i);
  return poses;
}

TEST(SynthRoom, GroundTruthProjectsPanelCornersOntoTheRenderedTextures) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  const RoomScene scene = MakeRoomScene();
  const calib::Camera camera = RoomCamera();
  RoomRenderer renderer(render::testing::SharedContext(), scene, camera, 4);
  int checked = 0;
  double worst = 0;
  cv::Point2d sum(0, 0);
  for (const auto& [seed, t] : Poses()) {
    const calib::Pose pose = RoomPath(10, seed).At(t);
    cv::Mat grey;
    cv::cvtColor(renderer.Render(pose), grey, cv::COLOR_BGR2GRAY);
    for (const RoomPanel& panel : scene.panels) {
      const PanelCheck check = CheckPanel(grey, scene.textures[panel.texture], panel, camera, pose);
      if (!check.usable || check.ncc < 0.8) continue;  // off-screen, too small, or behind a box
      ++checked;
      const double error = std::hypot(check.shift.x, check.shift.y);
      worst = std::max(worst, error);
      sum += check.shift;
      EXPECT_LT(error, 0.5) << "shift (" << check.shift.x << ", " << check.shift.y << ") " << panel.image_name
                            << " at seed " << seed << ", t = " << t << ", NCC " << check.ncc;
    }
  }
  std::printf("%d panel views checked, worst shift %.3f px, mean (%.3f, %.3f) px\n", checked, worst,
              sum.x / checked, sum.y / checked);
  ASSERT_GE(checked, 12);
  // Texture filtering differs between llvmpipe (trilinear + anisotropic) and the reference
  // warp, which scatters single panels by up to ~0.35 px; a wrong convention would instead
  // shift all of them the same way.
  EXPECT_LT(std::abs(sum.x / checked), 0.1);
  EXPECT_LT(std::abs(sum.y / checked), 0.1);
}

// The room's light as `arview place` measures it for the demo: from keyframes of the orbit
// walk's first lap (the mapped one), at the demo character's middle, through the room's exact
// geometry (the demo measures it through the planes of its map, which has no ceiling: the
// evenly lit room's light then points below the floor, docs/render.md). Lit by the window, the
// light comes from above the floor and from the window's side (+y), so the character casts a
// shadow away from it.
DominantLight DemoRoomLight(SynthLighting lighting) {
  const RoomScene scene = MakeRoomScene(kOpenCvDocData, lighting);
  std::vector<Eigen::Vector3f> triangles;
  for (const render::TriangleBatch& batch : scene.batches)
    for (const render::SceneVertex& v : batch.vertices) triangles.emplace_back(v.position[0], v.position[1], v.position[2]);
  const TriangleBvh geometry(std::move(triangles));
  const OrbitWalk walk(1340 / 30.0, 1, OrbitWalkOptions{});
  RoomRenderer renderer(render::testing::SharedContext(), scene, RoomCamera(), 4);
  std::vector<LightKeyframe> keyframes;
  for (int frame = 0; frame < 670; frame += 14) {
    const calib::Pose pose = walk.At(frame / 30.0);
    keyframes.push_back({RoomCamera(), pose, renderer.Render(pose)});
  }
  return EstimateRoomLight(keyframes, geometry, walk.Subject() + Eigen::Vector3d(0, 0, 0.86)).dominant;
}

double ElevationDegrees(const Eigen::Vector3d& direction) { return std::asin(direction.z()) * 180 / M_PI; }

TEST(SynthRoom, TheWindowLitRoomsLightComesFromAboveTheFloorOnTheWindowsSide) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  const DominantLight even = DemoRoomLight(SynthLighting::kEven);
  const DominantLight window = DemoRoomLight(SynthLighting::kWindow);
  std::printf("dominant light: evenly lit %.1f deg above the floor (%.2f %.2f %.2f), window-lit %.1f deg (%.2f %.2f %.2f)\n",
              ElevationDegrees(even.direction), even.direction.x(), even.direction.y(), even.direction.z(),
              ElevationDegrees(window.direction), window.direction.x(), window.direction.y(), window.direction.z());
  EXPECT_GT(ElevationDegrees(window.direction), 25);
  EXPECT_GT(window.direction.y(), 0.2);  // towards the window's wall
  EXPECT_GT(window.color.minCoeff(), 0.1);
}

// A short noisy walk: 4 frames, seed 5, sensor noise on.
SynthRoomOptions FourNoisyFrames(const fs::path& out) {
  SynthRoomOptions options;
  options.frames = 4;
  options.seed = 5;
  options.noise_sigma = 2.0;
  options.gl.threads = 2;  // auto
  options.out = out;
  return options;
}

TEST(SynthRoom, WritesALoadableDeterministicRecording) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  TempDir a, b, c;
  SynthRoomOptions options = FourNoisyFrames(a.path);
  SynthesizeRoom(options);
  options.out = b.path;
  SynthesizeRoom(options);
  options.out = c.path;
  options.seed = 6;
  SynthesizeRoom(options);

  const recordings::Recording recording = recordings::LoadRecording(a.path);
  ASSERT_EQ(recording.frames.size(), 4u);
  ASSERT_TRUE(recording.groundtruth.has_value());
  ASSERT_EQ(recording.groundtruth->size(), 4u);
  EXPECT_NEAR(recording.frames[3].timestamp, 0.1, 1e-9);
  EXPECT_EQ(recording.camera.width, 640);
  EXPECT_DOUBLE_EQ(recording.camera.fx, RoomCamera().fx);
  const calib::Pose expected = RoomPath(4 / 30.0, 5).At(2 / 30.0);
  EXPECT_LT(((*recording.groundtruth)[2].pose.Center() - expected.Center()).norm(), 1e-9);
  EXPECT_EQ(recording.ReadImage(0).size(), cv::Size(640, 480));

  EXPECT_EQ(Bytes(a.path / "frames/000003.png"), Bytes(b.path / "frames/000003.png"));
  EXPECT_NE(Bytes(a.path / "frames/000003.png"), Bytes(c.path / "frames/000003.png"));
}

// Another lens (--focal-scale, --distortion): the frame a wide, barrel-distorted lens sees,
// undistorted by OpenCV's own maps (cv::initUndistortRectifyMap) into the pinhole room camera,
// is what that camera renders; and camera.yaml says the lens.
TEST(SynthRoom, ADistortedLensSeesWhatOpenCvsModelSays) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  SynthRoomOptions options;
  options.focal_scale = 0.8;
  options.distortion = {-0.25, 0.07, 0.001, -0.0005, 0};
  const calib::Camera lens = SynthCamera(options), plain = RoomCamera();
  EXPECT_DOUBLE_EQ(lens.fx, 0.8 * plain.fx);
  const DistortedRoom distorted(lens);
  EXPECT_GT(distorted.pinhole().width, lens.width);  // barrel: the edge rays are wider than a pinhole's
  const RoomScene scene = MakeRoomScene();
  const calib::Pose pose = RoomPath(10, 1).At(3);
  RoomRenderer wide(render::testing::SharedContext(), scene, distorted.pinhole(), 4);
  const cv::Mat seen = distorted.Distort(wide.Render(pose));
  ASSERT_EQ(seen.size(), cv::Size(640, 480));
  RoomRenderer pinhole(render::testing::SharedContext(), scene, plain, 4);
  const cv::Mat truth = pinhole.Render(pose);
  cv::Mat map_x, map_y, undistorted;
  cv::initUndistortRectifyMap(cv::Mat(lens.K()), lens.DistCoeffs(), cv::noArray(), cv::Mat(plain.K()), plain.Size(),
                              CV_32FC1, map_x, map_y);
  cv::remap(seen, undistorted, map_x, map_y, cv::INTER_LINEAR);
  const cv::Rect inner(80, 60, 480, 360);
  cv::Mat grey_truth, grey_undistorted, grey_seen;
  cv::cvtColor(truth(inner), grey_truth, cv::COLOR_BGR2GRAY);
  cv::cvtColor(undistorted(inner), grey_undistorted, cv::COLOR_BGR2GRAY);
  cv::cvtColor(seen(inner), grey_seen, cv::COLOR_BGR2GRAY);
  const double after = cv::mean(cv::abs(grey_truth - grey_undistorted))[0] + cv::mean(cv::abs(grey_undistorted - grey_truth))[0];
  const double before = cv::mean(cv::abs(grey_truth - grey_seen))[0] + cv::mean(cv::abs(grey_seen - grey_truth))[0];
  std::printf("[distorted lens] mean grey difference from the pinhole's: %.2f undistorted, %.2f as seen\n", after, before);
  // What is left is the two resamplings' blur (the lens's frame has 0.8 of the pinhole's
  // resolution): 6.4 grey levels measured, against 65.6 for the frame as the lens saw it.
  EXPECT_LT(after, 10.0);
  EXPECT_GT(before, 5 * after);

  TempDir dir;
  options = FourNoisyFrames(dir.path);
  options.focal_scale = 0.8;
  options.distortion = {-0.25, 0.07, 0.001, -0.0005, 0};
  SynthesizeRoom(options);
  const calib::Camera written = calib::LoadCamera(dir.path / "camera.yaml");
  EXPECT_DOUBLE_EQ(written.fx, lens.fx);
  EXPECT_DOUBLE_EQ(written.dist[0], -0.25);
  options.distortion = {-9.5, 0, 0, 0, 0};
  options.out = dir.path / "strong";
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  EXPECT_FALSE(fs::exists(options.out));  // refused before anything is written
}

// --subset renders some frames of the walk, each exactly as the whole recording has it.
TEST(SynthRoom, SubsetRendersTheWholeRecordingsFrames) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  TempDir whole, part, bad;
  SynthRoomOptions options = FourNoisyFrames(whole.path);
  SynthesizeRoom(options);
  options.out = part.path;
  options.frames_subset = "1,3";
  EXPECT_EQ(SynthesizeRoom(options).frames, 2);

  const recordings::Recording all = recordings::LoadRecording(whole.path);
  const recordings::Recording some = recordings::LoadRecording(part.path);
  ASSERT_EQ(some.frames.size(), 2u);
  ASSERT_EQ(some.groundtruth->size(), 2u);
  EXPECT_DOUBLE_EQ(some.frames[1].timestamp, all.frames[3].timestamp);
  EXPECT_EQ((*some.groundtruth)[0].pose.Center(), (*all.groundtruth)[1].pose.Center());
  EXPECT_EQ(Bytes(part.path / "frames/000003.png"), Bytes(whole.path / "frames/000003.png"));
  EXPECT_FALSE(fs::exists(part.path / "frames/000002.png"));

  options.out = bad.path;
  options.frames_subset = "2-4";  // frame 4 is past the walk's end
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  EXPECT_FALSE(fs::exists(bad.path / "frames.txt"));
}

// A tripod inserted into the walk: its frames repeat one pose exactly (only the noise differs),
// and the walk goes on after it where it stopped.
TEST(SynthRoom, AStillSegmentHoldsOnePoseAndTheWalkResumesWhereItStopped) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  TempDir dir;
  SynthRoomOptions options = FourNoisyFrames(dir.path);
  options.width = 160;
  options.height = 120;
  options.still_at_s = 1 / 30.0;
  options.still_s = 2 / 30.0;
  EXPECT_EQ(RecordingFrames(options), 6);
  EXPECT_EQ(SynthesizeRoom(options).frames, 6);
  const recordings::Recording r = recordings::LoadRecording(dir.path);
  ASSERT_EQ(r.groundtruth->size(), 6u);
  const RoomPath walk(4 / 30.0, 5);
  const auto& gt = *r.groundtruth;
  for (int i : {1, 2, 3}) {
    EXPECT_LT((gt[i].pose.Center() - walk.At(1 / 30.0).Center()).norm(), 1e-9) << i;
    EXPECT_LT(gt[i].pose.q_cw.angularDistance(walk.At(1 / 30.0).q_cw), 1e-9) << i;
  }
  EXPECT_LT((gt[5].pose.Center() - walk.At(3 / 30.0).Center()).norm(), 1e-9);
  EXPECT_NEAR(gt[5].timestamp, 5 / 30.0, 1e-9);  // as the TUM file prints it
  cv::Mat diff;
  cv::absdiff(r.ReadImage(1), r.ReadImage(2), diff);
  const double mean_diff = cv::mean(diff)[0];
  EXPECT_GT(mean_diff, 0.5) << "the sensor's noise differs from frame to frame";
  EXPECT_LT(mean_diff, 4.0) << "but the picture does not move";
  EXPECT_NE(Bytes(dir.path / "groundtruth.txt").find("still for 0.06667 s from 0.03333 s"), std::string::npos);
  options.still_at_s = 1.0;  // after the 4-frame walk's end
  options.overwrite = true;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
}

// The realistic-footage flags: a 1280x720 camera with the same field of view, JPEG frames, a
// gain change and a rolling shutter, each changing the image and none the ground truth.
TEST(SynthRoom, RealisticFootageFlags) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  const calib::Camera hd = RoomCamera(1280, 720);
  EXPECT_DOUBLE_EQ(hd.fx, 2 * RoomCamera().fx);
  EXPECT_DOUBLE_EQ(hd.cx, 643.5);  // (640 − 1)/2 + 2 at 640 wide, scaled in pixel centres
  TempDir plain, real;
  SynthRoomOptions options;
  options.frames = 2;
  options.width = 1280;
  options.height = 720;
  options.gl.threads = 2;  // auto
  options.out = plain.path;
  SynthesizeRoom(options);
  options.out = real.path;
  options.jpeg_quality = 80;
  options.gain_drift = 0.3;
  options.rolling_shutter_s = 0.02;
  SynthesizeRoom(options);
  const recordings::Recording a = recordings::LoadRecording(plain.path);
  const recordings::Recording b = recordings::LoadRecording(real.path);
  EXPECT_EQ(a.camera.Size(), cv::Size(1280, 720));
  EXPECT_EQ(b.ReadImage(1).size(), cv::Size(1280, 720));
  EXPECT_TRUE(fs::exists(real.path / "frames/000001.jpg"));
  EXPECT_LT(((*a.groundtruth)[1].pose.Center() - (*b.groundtruth)[1].pose.Center()).norm(), 1e-12);
  cv::Mat diff;
  cv::absdiff(a.ReadImage(1), b.ReadImage(1), diff);
  EXPECT_GT(cv::mean(diff)[0], 1.0) << "gain, JPEG and rolling shutter should change the frame";
  options.jpeg_quality = 101;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
}

TEST(SynthRoom, RefusesANonEmptyFolderAndBadOptions) {
  TempDir dir;
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "keep.txt") << "mine";
  SynthRoomOptions options;
  options.out = dir.path;
  options.frames = 1;
  options.gl.threads = 2;  // auto
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  EXPECT_TRUE(fs::exists(dir.path / "keep.txt"));
  options.frames = 0;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  options.frames = 1;
  options.noise_sigma = -1;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
}

TEST(SynthRoom, NamesAMissingPhoto) {
  TempDir dir;
  try {
    MakeRoomScene(dir.path);
    FAIL() << "expected render::RenderError";
  } catch (const render::RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("opencv-doc"), std::string::npos) << e.what();
  }
}

// A damaged room photo (here home.jpg cut short) was read by cv::imread, libjpeg printing its
// own line; now it is one RenderError naming the file, nothing printed.
TEST(SynthRoom, NamesADamagedPhotoAndLibjpegSaysNothing) {
  const fs::path photos = kOpenCvDocData;
  ARVIEW_REQUIRE_DATA_PATH(photos, "Debian package opencv-doc");
  TempDir dir;
  fs::create_directories(dir.path);
  for (const auto& entry : fs::directory_iterator(photos)) {
    fs::create_symlink(entry.path(), dir.path / entry.path().filename());
  }
  const fs::path damaged = dir.path / "home.jpg";
  const std::string whole = Bytes(photos / "home.jpg");
  fs::remove(damaged);
  std::ofstream(damaged, std::ios::binary) << whole.substr(0, whole.size() / 2);
  ::testing::internal::CaptureStderr();
  try {
    MakeRoomScene(dir.path);
    ADD_FAILURE() << "expected render::RenderError";
  } catch (const render::RenderError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(damaged.string() + ": the JPEG is cut short", 0), 0u) << e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace arview::synth

namespace arview::synth {
namespace {

TEST(SynthLights, TheLampDropsTwoStopsInOneFrameAndTheExposureStepsBackInThirds) {
  LightChanges lights;
  lights.lamp_off_s = 1.0;
  lights.lamp_on_s = 5.0;
  EXPECT_EQ(LampGain(lights, 0.99), 1.0);
  EXPECT_EQ(LampGain(lights, 1.0), kLampOffGain);
  EXPECT_EQ(LampGain(lights, 5.0), 1.0);
  EXPECT_EQ(ExposureGain(lights, 30, 100), 1.0) << "no auto-exposure: the exposure stays";
  lights.auto_exposure = true;
  EXPECT_EQ(ExposureGain(lights, 30, 38), 1.0) << "0.3 s before the camera reacts";
  double previous = 1.0;
  for (int frame = 39; frame < 100; ++frame) {
    const double gain = ExposureGain(lights, 30, frame);
    const double step_ev = std::log2(gain / previous);  // none, or a third (floating point's last bit aside)
    EXPECT_TRUE(std::abs(step_ev) < 1e-9 || std::abs(step_ev - 1.0 / 3) < 1e-9) << frame << ": " << step_ev;
    previous = gain;
  }
  EXPECT_NEAR(ExposureGain(lights, 30, 100), 4.0, 1e-9) << "the two stops made up";
}

TEST(SynthWalkers, WalkersKeepTheirDistanceFromTheCameraAndWalkAtTheClipsPace) {
  WalkersOptions walkers;
  walkers.count = 3;
  walkers.spot = {-0.2, 0.25};
  // 1.3 m from the spot the circles shrink to keep 1 m; at the demo's close approach, 1.15 m, to
  // their smallest, 0.2 m, which leaves 0.95 m.
  const Eigen::Vector3d near_camera(-0.2 + 1.3, 0.25, 1.5), close_camera(-0.2 + 1.15, 0.25, 1.5);
  for (int i = 0; i < 3; ++i) {
    for (double t = 0; t < 10; t += 0.1) {
      EXPECT_GE((WalkerAt(walkers, i, t, near_camera).position - near_camera).head<2>().norm(), kKeepAwayFromCamera - 1e-9);
      const WalkerState s = WalkerAt(walkers, i, t, close_camera);
      EXPECT_GE((s.position - close_camera).head<2>().norm(), 0.95 - 1e-9);
      EXPECT_NEAR(s.heading.norm(), 1.0, 1e-12);
      EXPECT_NEAR(s.heading.dot((s.position - Eigen::Vector3d(-0.2, 0.25, 0)).normalized()), 0.0, 1e-9) << "along its circle";
    }
    const Eigen::Vector3d far_camera(3, 2, 1.5);
    const double step = (WalkerAt(walkers, i, 1.0, far_camera).position - WalkerAt(walkers, i, 1.01, far_camera).position).norm();
    EXPECT_NEAR(step / 0.01, figure::kWalkSpeed, 0.01);
  }
}

TEST(SynthWalkers, SunWithoutTheWindowAndALampOnBeforeItIsOffAreRefused) {
  TempDir dir;
  SynthRoomOptions options;
  options.out = dir.path / "r";
  options.frames = 2;
  options.lights.sun = true;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  options.lights.sun = false;
  options.lights.lamp_on_s = 0.01;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
  options.lights.lamp_on_s = -1;
  options.walkers.count = 4;
  EXPECT_THROW(SynthesizeRoom(options), render::RenderError);
}

}  // namespace
}  // namespace arview::synth
