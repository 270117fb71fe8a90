// The figure's face (issue 52): eye, lid, brow and jaw joints under the head that its clips
// leave at rest, and its eyes turned to the camera by gaze (anim/gaze.h) while the head stays
// where the look-at chain puts it.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>

#include "anim/pose.h"
#include "anim_authoring/animator_builder.h"
#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "figure/humanoid.h"

namespace arview::figure {
namespace {

const char* const kFaceJoints[] = {"LeftEye",  "LeftUpperLid",  "LeftLowerLid",  "LeftBrow", "RightEye",
                                   "RightUpperLid", "RightLowerLid", "RightBrow", "Jaw"};

TEST(FigureFace, EyeLidBrowAndJawJointsHangFromTheHeadAndTheClipsLeaveThemAtRest) {
  const anim::Character c = MakeHumanoid();
  const int head = c.skeleton.Find("Head");
  for (const char* name : kFaceJoints) {
    const int j = c.skeleton.Find(name);
    ASSERT_GE(j, 0) << name;
    EXPECT_EQ(c.skeleton.parents[j], head) << name;
    for (const anim::Clip& clip : c.clips)
      for (double t = 0; t <= clip.duration; t += clip.duration / 7) {
        anim::LocalPose pose(c.skeleton.size());
        ASSERT_TRUE((anim::SamplingJob{&c.skeleton, &clip, t, false, &pose}.Run()));
        EXPECT_LT(pose.rigid[j].Rotation().angularDistance(c.skeleton.rest[j].rotation), 1e-9) << clip.name << " " << name;
        EXPECT_LT((pose.rigid[j].Translation() - c.skeleton.rest[j].translation).norm(), 1e-9) << clip.name << " " << name;
      }
  }
  // The body's joints keep the indices they had before the face had joints: the face's come after.
  EXPECT_EQ(c.skeleton.Find("RightToe_End"), 28);
  EXPECT_EQ(c.skeleton.Find("LeftEye"), 29);
  EXPECT_EQ(c.skeleton.size(), 38);
  EXPECT_TRUE(anim::FindGazeRig(c.skeleton).valid());
}

std::string FigureScene(const std::string& gaze) {
  std::string text = "characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n    gaze: " + gaze + "\n    keys:\n";
  for (int k = 0; k < 8; ++k) text += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
  return text;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

// The viewer in front within the eyes' range (0.6 to 2 m away, at and around eye height, up to
// 40° to either side): during mutual gaze both eyes point within 2° of the camera centre, and
// the head's joints are exactly those of the same scene without gaze.
TEST(FigureFace, EyesMeetTheCameraAndTheHeadStaysWhereTheLookAtChainPutsIt) {
  RegisterBuiltinCharacters();
  const authoring::Scene with = authoring::ParseScene(FigureScene("{mode: listening, seed: 3}"), "figure.yaml");
  const authoring::Scene without = authoring::ParseScene(FigureScene("{enabled: false}"), "figure.yaml");
  authoring::AnimatedCharacter a(with.characters[0]), b(without.characters[0]);
  ASSERT_TRUE(a.gaze().has_value());
  ASSERT_FALSE(b.gaze().has_value());
  auto animator_a = authoring::BuildAnimator(a), animator_b = authoring::BuildAnimator(b);
  const anim::Placement placement = with.characters[0].placement();
  const anim::GazeRig rig = a.gaze()->rig;
  const int head = a.character().skeleton.Find("Head");
  double worst = 0, worst_head = 0;
  int frames = 0, mutual = 0;
  double t = 0;
  for (double distance : {0.6, 1.0, 2.0})
    for (double height : {1.5, 1.64, 1.75})
      for (double azimuth : {-40.0, -15.0, 0.0, 25.0, 40.0})
        for (int f = 0; f < 90; ++f, t += 1.0 / 30) {
          const Eigen::Vector3d camera(distance * std::sin(azimuth * M_PI / 180), height, distance * std::cos(azimuth * M_PI / 180));
          anim::FrameInputs in;
          in.viewpoint = placement.ViewpointFromCamera(camera);
          in.distance = placement.FloorDistance(camera);
          in.viewer = placement.MapToModel(camera);
          const anim::AnimatorFrame& fa = animator_a->Update(t, in);
          const anim::AnimatorFrame& fb = animator_b->Update(t, in);
          ++frames;
          worst_head = std::max(worst_head, (fa.model[head] - fb.model[head]).cwiseAbs().maxCoeff());
          EXPECT_TRUE(fa.gaze.active);
          EXPECT_FALSE(fb.gaze.active);
          if (!fa.gaze.eyes_on_viewer) continue;
          ++mutual;
          for (const anim::GazeRig::Side& side : rig.eyes) {
            const Eigen::Matrix4d& m = fa.model[side.eye];
            const Eigen::Vector3d forward = m.block<3, 3>(0, 0) * Eigen::Vector3d::UnitZ();
            worst = std::max(worst, AngleDeg(forward, in.viewer - m.block<3, 1>(0, 3)));
          }
        }
  std::printf("[gaze] builtin:figure listening, viewer in front 0.6-2 m: %d of %d frames in mutual gaze, eyes within %.4f deg "
              "of the camera centre; head joint differs from no-gaze by %.2g\n",
              mutual, frames, worst, worst_head);
  EXPECT_GT(mutual, frames / 2);
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(worst_head, 0.0);
}

// The jaw opens the mouth: turned 15° down it carries the lower lip and the chin down and leaves
// the upper lip where it is.
TEST(FigureFace, TheJawOpensTheLips) {
  const anim::Character c = MakeHumanoid();
  const int jaw = c.skeleton.Find("Jaw");
  anim::LocalPose pose = anim::LocalPose::Rest(c.skeleton);
  pose.rigid[jaw] = anim::DualQuatd::FromRotationTranslation(Eigen::Quaterniond(Eigen::AngleAxisd(15 * M_PI / 180, Eigen::Vector3d::UnitX())),
                                                            c.skeleton.rest[jaw].translation);
  std::vector<Eigen::Matrix4d> model(c.skeleton.size());
  ASSERT_TRUE((anim::LocalToModelJob{&c.skeleton, &pose, model}.Run()));
  std::vector<Eigen::Matrix4f> skin(c.skeleton.size());
  ASSERT_TRUE((anim::SkinningMatricesJob{&c.skeleton, model, skin, {}}.Run()));
  double lower_lip_drop = 0, upper_lip_move = 0;
  for (const anim::Mesh& m : c.meshes) {
    if (m.name != "face_lips") continue;
    std::vector<Eigen::Vector3f> out(m.vertex_count());
    ASSERT_TRUE((anim::SkinningJob{&m, anim::SkinningMethod::kLinear, skin, {}, out, {}}.Run()));
    for (int v = 0; v < m.vertex_count(); ++v) {
      const bool lower = m.joints[v][0] == jaw && m.weights[v][0] > 0.5f;
      if (lower) lower_lip_drop = std::max(lower_lip_drop, static_cast<double>(m.positions[v].y() - out[v].y()));
      else upper_lip_move = std::max(upper_lip_move, static_cast<double>((out[v] - m.positions[v]).norm()));
    }
  }
  EXPECT_GT(lower_lip_drop, 0.015);  // the lips part by more than the 9 mm of the two lips' height
  EXPECT_EQ(upper_lip_move, 0.0);
}

}  // namespace
}  // namespace arview::figure
