// The figure's face rendered (issue 52): a close-up at 0.6 m with the camera 20° to the
// figure's left, the head held forward (a rest-pose key): with gaze the irises move toward the
// camera in the image, and on a blink frame the lids hide the eyes.

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "figure/face_targets.h"
#include "figure/humanoid.h"
#include "render/ar_renderer.h"
#include "render/test_scene.h"

namespace arview::figure {
namespace {

constexpr double kSideDeg = 20, kDistance = 0.6;

std::string RestScene(const std::string& gaze) {
  return "characters:\n  - asset: builtin:figure\n    gaze: " + gaze + "\n    keys:\n      - azimuth: 0\n        pose: rest\n";
}

struct Shot {
  cv::Mat image;
  std::array<Eigen::Vector2d, 2> eye_px;  // the eyes' centres projected
  double eye_radius_px = 0;
};

// The figure at `t`, seen from 0.6 m in front of its eyes, 20° toward its left (+X), at eye height.
// `morph`: target weights set over the frame's (none by default).
Shot Render(const std::string& gaze, double t, bool* eyes_on_viewer = nullptr, const std::vector<TargetWeight>& morph = {}) {
  RegisterBuiltinCharacters();
  const authoring::Scene scene = authoring::ParseScene(RestScene(gaze), "face.yaml");
  authoring::AnimatedCharacter figure(scene.characters[0]);
  const anim::Skeleton& sk = figure.character().skeleton;
  const anim::AnimatorFrame& rest = figure.Update(Eigen::Vector3d::UnitZ(), 0);
  const Eigen::Vector3d left = rest.model[sk.Find("LeftEye")].block<3, 1>(0, 3);
  const Eigen::Vector3d right = rest.model[sk.Find("RightEye")].block<3, 1>(0, 3);
  const Eigen::Vector3d between = 0.5 * (left + right);
  const Eigen::Vector3d camera_at =
      between + kDistance * Eigen::Vector3d(std::sin(kSideDeg * M_PI / 180), 0, std::cos(kSideDeg * M_PI / 180));
  const Eigen::Vector3d z = (between - camera_at).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r << x, y, z;
  const calib::Pose pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r), camera_at);
  const calib::Camera camera = calib::Camera::Pinhole(640, 480, 600, 600, 320, 240);
  const anim::Placement placement = scene.characters[0].placement();
  anim::AnimatorFrame frame = figure.Update(placement.ViewpointFromCamera(camera_at), t, placement.MapToModel(camera_at));
  std::vector<float> weights(frame.morph_weights.begin(), frame.morph_weights.end());
  for (const TargetWeight& w : morph) weights.at(sk.FindMorphTarget(w.target)) = w.weight;
  frame.morph_weights = weights;
  if (eyes_on_viewer) *eyes_on_viewer = frame.gaze.eyes_on_viewer;
  render::ArOptions options;
  options.shadow = false;
  render::ArRenderer renderer(render::testing::SharedContext(), camera, options);
  renderer.AddCharacter(figure.character(), placement);
  const anim::AnimatorFrame* frames[] = {&frame};
  Shot shot;
  shot.image = renderer.Render({}, pose, frames);
  shot.eye_px = {camera.Project(pose.ToCamera(left)), camera.Project(pose.ToCamera(right))};
  shot.eye_radius_px = 600 * 0.012 / kDistance;
  return shot;
}

bool IsIris(const cv::Vec3b& bgr) { return bgr[0] > bgr[2] + 25 && bgr[0] > 40; }
bool IsWhite(const cv::Vec3b& bgr) { return bgr[0] > 150 && bgr[1] > 150 && bgr[2] > 150 && std::abs(bgr[2] - bgr[0]) < 45; }

struct EyeLook {
  double iris_x = 0;   // the iris pixels' centroid, relative to the eye's projected centre
  int iris = 0, white = 0;
};

EyeLook Look(const Shot& shot, int eye) {
  EyeLook look;
  const int r = static_cast<int>(std::ceil(1.6 * shot.eye_radius_px));
  const Eigen::Vector2d c = shot.eye_px[eye];
  double sum = 0;
  for (int v = static_cast<int>(c.y()) - r; v <= static_cast<int>(c.y()) + r; ++v)
    for (int u = static_cast<int>(c.x()) - r; u <= static_cast<int>(c.x()) + r; ++u) {
      if (u < 0 || v < 0 || u >= shot.image.cols || v >= shot.image.rows) continue;
      const cv::Vec3b& p = shot.image.at<cv::Vec3b>(v, u);
      if (IsIris(p)) {
        ++look.iris;
        sum += u - c.x();
      }
      look.white += IsWhite(p);
    }
  look.iris_x = look.iris ? sum / look.iris : 0;
  return look;
}

void Save(const Shot& shot, const char* name) {
  if (const char* dir = std::getenv("ARVIEW_TEST_OUTPUT")) cv::imwrite(std::string(dir) + "/" + name, shot.image);
}

TEST(FigureFaceRender, IrisesTurnTowardTheCameraAndLidsCloseOnABlink) {
  bool mutual = false;
  const Shot ahead = Render("{enabled: false}", 0.5);
  const Shot looking = Render("{mode: listening, seed: 1}", 0.5, &mutual);
  ASSERT_TRUE(mutual) << "the first fixation is on the viewer";
  Save(ahead, "face_ahead.png");
  Save(looking, "face_looking.png");
  for (int eye = 0; eye < 2; ++eye) {
    const EyeLook a = Look(ahead, eye), b = Look(looking, eye);
    std::printf("[face] eye %d: iris %d px at %+.2f px (gaze off) -> %d px at %+.2f px (on the camera); white %d -> %d px\n", eye,
                a.iris, a.iris_x, b.iris, b.iris_x, a.white, b.white);
    ASSERT_GT(a.iris, 10);
    ASSERT_GT(b.iris, 10);
    // The camera is at the figure's left, the image's right: the iris moves right, by about the
    // eye's radius times sin 20° (4 px at 0.6 m) less what perspective takes.
    EXPECT_GT(b.iris_x - a.iris_x, 1.5) << "eye " << eye;
  }
  // A blink frame: the first blink of the same seed, at its closed instant.
  anim::GazeOptions options;
  options.seed = 1;
  anim::GazeLog log;
  anim::GazeBehaviour behaviour(options);
  behaviour.set_log(&log);
  behaviour.Advance(60);
  ASSERT_FALSE(log.blinks.empty());
  const double shut_at = log.blinks.front().start + 0.05;
  std::printf("[face] the first blink of seed 1 is shut at t = %.4f s\n", shut_at);
  const Shot shut = Render("{mode: listening, seed: 1}", shut_at);
  Save(shut, "face_blink.png");
  for (int eye = 0; eye < 2; ++eye) {
    const EyeLook open = Look(looking, eye), closed = Look(shut, eye);
    std::printf("[face] eye %d on a blink: iris %d -> %d px, white %d -> %d px\n", eye, open.iris, closed.iris, open.white,
                closed.white);
    EXPECT_LE(closed.iris, open.iris / 10) << "eye " << eye;
    EXPECT_LE(closed.white, open.white / 10 + 2) << "eye " << eye;
  }
}

// The pixels that differ by more than 30 levels (any channel) between two shots.
int ChangedPixels(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  int changed = 0;
  for (int v = 0; v < diff.rows; ++v)
    for (int u = 0; u < diff.cols; ++u) {
      const cv::Vec3b& d = diff.at<cv::Vec3b>(v, u);
      changed += std::max({d[0], d[1], d[2]}) > 30;
    }
  return changed;
}

// A weighted target changes the face's pixels (the vertex shader applies it), and only there:
// the changed pixels lie below the eyes for jawOpen, around and above them for browInnerUp.
TEST(FigureFaceRender, AWeightedTargetChangesTheFacesPixels) {
  const Shot rest = Render("{enabled: false}", 0.5);
  const Shot jaw = Render("{enabled: false}", 0.5, nullptr, {{"jawOpen", 1.0f}});
  const Shot happy = Render("{enabled: false}", 0.5, nullptr, ExpressionWeights(Expression::kHappy, 1));
  Save(jaw, "face_jawOpen.png");
  Save(happy, "face_happy.png");
  const int eye_row = static_cast<int>(std::max(rest.eye_px[0].y(), rest.eye_px[1].y()));
  cv::Mat diff;
  cv::absdiff(rest.image, jaw.image, diff);
  int above = 0, below = 0;
  for (int v = 0; v < diff.rows; ++v)
    for (int u = 0; u < diff.cols; ++u) {
      const cv::Vec3b& d = diff.at<cv::Vec3b>(v, u);
      if (std::max({d[0], d[1], d[2]}) > 30) (v > eye_row ? below : above) += 1;
    }
  const int changed_happy = ChangedPixels(rest.image, happy.image);
  std::printf("[face] jawOpen changes %d px below the eyes and %d above; happy changes %d px\n", below, above, changed_happy);
  EXPECT_GT(below, 300);
  EXPECT_EQ(above, 0);
  EXPECT_GT(changed_happy, 100);
  EXPECT_EQ(ChangedPixels(rest.image, Render("{enabled: false}", 0.5).image), 0) << "the same render twice";
}

}  // namespace
}  // namespace arview::figure
