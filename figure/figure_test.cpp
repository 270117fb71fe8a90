#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <set>

#include "anim_authoring/character_builder.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/lookat.h"
#include "anim/pose.h"
#include "anim_authoring/scene.h"
#include "figure/humanoid.h"

namespace arview::figure {
namespace {

const anim::Character& Figure() {
  static const anim::Character c = MakeHumanoid();
  return c;
}

std::vector<Eigen::Matrix4d> ModelPose(const anim::Character& c, const anim::Clip* clip, double t) {
  anim::LocalPose pose(c.skeleton.size());
  if (clip) EXPECT_TRUE((anim::SamplingJob{&c.skeleton, clip, t, false, &pose}.Run()));
  else pose = anim::LocalPose::Rest(c.skeleton);
  std::vector<Eigen::Matrix4d> model(c.skeleton.size());
  EXPECT_TRUE((anim::LocalToModelJob{&c.skeleton, &pose, model}.Run()));
  return model;
}

Eigen::Vector3d JointAt(const anim::Character& c, const std::vector<Eigen::Matrix4d>& model, const std::string& name) {
  const int j = c.skeleton.Find(name);
  EXPECT_GE(j, 0) << name;
  return model[j].block<3, 1>(0, 3);
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

TEST(Figure, SkeletonUsesHumanoidNamesThatTheLookAtChainFinds) {
  const anim::Skeleton& sk = Figure().skeleton;
  for (const char* name : {"Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm",
                           "LeftHand", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot",
                           "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"})
    EXPECT_GE(sk.Find(name), 0) << name;
  const std::vector<std::string> chain = authoring::DefaultLookAtChain(sk);
  ASSERT_FALSE(chain.empty());
  EXPECT_EQ(chain.front(), "Hips");
  EXPECT_EQ(chain.back(), "Head");
  EXPECT_NE(std::find(chain.begin(), chain.end(), "Neck"), chain.end());
  for (int j = 0; j < sk.size(); ++j) EXPECT_LT(sk.parents[j], j);
}

TEST(Figure, MeshesAreValidColouredAndAFewThousandTriangles) {
  const anim::Character& c = Figure();
  std::size_t triangles = 0;
  std::set<int> materials;
  for (const anim::Mesh& m : c.meshes) {
    ASSERT_EQ(m.normals.size(), m.positions.size()) << m.name;
    ASSERT_EQ(m.joints.size(), m.positions.size()) << m.name;
    ASSERT_EQ(m.weights.size(), m.positions.size()) << m.name;
    ASSERT_EQ(m.indices.size() % 3, 0u);
    for (std::uint32_t i : m.indices) ASSERT_LT(i, m.positions.size()) << m.name;
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      EXPECT_NEAR(m.weights[v].sum(), 1.0f, 1e-5f) << m.name;
      EXPECT_NEAR(m.normals[v].norm(), 1.0f, 1e-4f) << m.name;
      for (int k = 0; k < 4; ++k) EXPECT_LT(m.joints[v][k], c.skeleton.size());
    }
    triangles += m.indices.size() / 3;
    ASSERT_GE(m.material, 0);
    materials.insert(m.material);
  }
  EXPECT_GT(triangles, 3000u);
  EXPECT_LT(triangles, 12000u);
  EXPECT_GE(materials.size(), 6u);  // skin, shirt, trousers, shoes, hair, eyes, lips
  // Distinct colours: the figure is not one grey.
  for (int a : materials)
    for (int b : materials)
      if (a < b) {
        EXPECT_GT((c.materials[a].base_color - c.materials[b].base_color).head<3>().norm(), 0.05f);
      }
}

// Every part is wound counter-clockwise seen from outside: closed parts enclose a positive
// signed volume (each part's own, so a mesh of several parts sums positives), the open hair
// shell's faces point away from its centre, and face normals agree with the vertex normals.
TEST(Figure, TrianglesFaceOutward) {
  for (const anim::Mesh& m : Figure().meshes) {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto& p : m.positions) centre += p;
    centre /= static_cast<float>(m.positions.size());
    double volume = 0;
    int outward = 0, agree = 0, counted = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
      const Eigen::Vector3f a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
      volume += (a - centre).dot((b - centre).cross(c - centre)) / 6.0;
      const Eigen::Vector3f n = (b - a).cross(c - a);
      if (n.norm() < 1e-12f) continue;
      ++counted;
      outward += n.dot((a + b + c) / 3 - centre) > 0;
      agree += n.dot(m.normals[m.indices[t]] + m.normals[m.indices[t + 1]] + m.normals[m.indices[t + 2]]) > 0;
    }
    if (m.name == "hair_hair") EXPECT_GT(outward, 0.9 * counted) << m.name;
    else EXPECT_GT(volume, 0) << m.name;
    EXPECT_EQ(agree, counted) << m.name;
  }
}

TEST(Figure, RestPoseSkinsToTheMeshAndStandsOnTheFloor) {
  const anim::Character& c = Figure();
  const std::vector<Eigen::Matrix4d> model = ModelPose(c, nullptr, 0);
  std::vector<Eigen::Matrix4f> skin(c.skeleton.size());
  ASSERT_TRUE((anim::SkinningMatricesJob{&c.skeleton, model, skin, {}}.Run()));
  float lo = 1e9f, hi = -1e9f;
  for (const anim::Mesh& m : c.meshes) {
    std::vector<Eigen::Vector3f> out(m.vertex_count());
    ASSERT_TRUE((anim::SkinningJob{&m, anim::SkinningMethod::kLinear, skin, {}, out, {}}.Run()));
    for (int v = 0; v < m.vertex_count(); ++v) {
      EXPECT_LT((out[v] - m.positions[v]).norm(), 1e-5f);
      lo = std::min(lo, m.positions[v].y());
      hi = std::max(hi, m.positions[v].y());
    }
  }
  EXPECT_NEAR(lo, 0.0f, 0.01f);
  EXPECT_NEAR(hi - lo, 1.75f, 0.03f);
}

TEST(Figure, ClipsLoopOrReturnToTheStartPosture) {
  const anim::Character& c = Figure();
  ASSERT_EQ(c.clips.size(), 5u);
  const std::vector<Eigen::Matrix4d> idle_start = ModelPose(c, c.FindClip("Idle"), 0);
  for (const anim::Clip& clip : c.clips) {
    const std::vector<Eigen::Matrix4d> start = ModelPose(c, &clip, 0), end = ModelPose(c, &clip, clip.duration);
    for (int j = 0; j < c.skeleton.size(); ++j) {
      // First and last keys give the same pose (loops are seamless; one-shots end at rest).
      EXPECT_LT((start[j] - end[j]).cwiseAbs().maxCoeff(), 2e-3) << clip.name << " " << c.skeleton.names[j];
      // Every clip starts within a few millimetres of Idle's posture: they cross-fade cleanly.
      EXPECT_LT((start[j].block<3, 1>(0, 3) - idle_start[j].block<3, 1>(0, 3)).norm(), 0.02)
          << clip.name << " " << c.skeleton.names[j];
    }
  }
}

TEST(Figure, TheWalkLoopsItsFeetSwingInAntiphaseAndItIsNotAmongTheBlendedClips) {
  const anim::Character& c = Figure();
  EXPECT_EQ(c.FindClip("Walk"), nullptr) << "a scene blends the character's clips; the walk is for walkers";
  const anim::Clip walk = MakeHumanoidWalk();
  EXPECT_NEAR(walk.duration, kWalkCycle, 1e-9);
  const std::vector<Eigen::Matrix4d> start = ModelPose(c, &walk, 0), end = ModelPose(c, &walk, walk.duration);
  for (int j = 0; j < c.skeleton.size(); ++j) EXPECT_LT((start[j] - end[j]).cwiseAbs().maxCoeff(), 2e-3) << c.skeleton.names[j];
  double most_apart = 0;
  for (double t = 0; t < kWalkCycle; t += kWalkCycle / 20) {
    const std::vector<Eigen::Matrix4d> m = ModelPose(c, &walk, t);
    const double left = JointAt(c, m, "LeftFoot").z(), right = JointAt(c, m, "RightFoot").z();
    EXPECT_LT(left * right, 1e-4) << "one foot ahead of the hips, the other behind, at " << t;
    most_apart = std::max(most_apart, std::abs(left - right));
  }
  EXPECT_GT(most_apart, 0.8 * kStride) << "the feet swing about a stride apart";
}

TEST(Figure, WeightShiftKeepsTheFeetPlantedAndMovesTheHips) {
  const anim::Character& c = Figure();
  const anim::Clip* shift = c.FindClip("WeightShift");
  ASSERT_TRUE(shift);
  const std::vector<Eigen::Matrix4d> rest = ModelPose(c, nullptr, 0);
  double hips_travel = 0;
  for (double t = 0; t <= shift->duration; t += 0.25) {
    const std::vector<Eigen::Matrix4d> m = ModelPose(c, shift, t);
    for (const char* foot : {"LeftFoot", "RightFoot"}) {
      const Eigen::Vector3d d = JointAt(c, m, foot) - JointAt(c, rest, foot);
      EXPECT_LT(std::hypot(d.x(), d.z()), 0.015) << foot << " at " << t;  // no sliding
      EXPECT_GT(d.y(), -0.002) << foot << " at " << t;                       // never through the floor
    }
    hips_travel = std::max(hips_travel, std::abs(JointAt(c, m, "Hips").x()));
  }
  EXPECT_GT(hips_travel, 0.03);
}

TEST(Figure, WaveRaisesTheRightHandAboveTheHeadAndPointAimsAhead) {
  const anim::Character& c = Figure();
  const std::vector<Eigen::Matrix4d> wave = ModelPose(c, c.FindClip("Wave"), 1.2);
  EXPECT_GT(JointAt(c, wave, "RightHand").y(), JointAt(c, wave, "Head").y());
  EXPECT_LT(JointAt(c, wave, "RightHand").x(), -0.2);  // the right hand is on the figure's right (−X)
  const std::vector<Eigen::Matrix4d> point = ModelPose(c, c.FindClip("Point"), 1.5);
  const Eigen::Vector3d arm = JointAt(c, point, "RightHand") - JointAt(c, point, "RightArm");
  EXPECT_LT(AngleDeg(arm, Eigen::Vector3d::UnitZ()), 15.0);
  EXPECT_NEAR(JointAt(c, point, "RightHand").y(), JointAt(c, point, "RightArm").y(), 0.1);
}

TEST(Figure, LoadsAsABuiltinAssetInScenes) {
  RegisterBuiltinCharacters();
  const anim::Character c = authoring::LoadCharacter("builtin:figure");
  EXPECT_EQ(c.source, "builtin:figure");
  EXPECT_EQ(c.meshes.size(), Figure().meshes.size());
  try {
    authoring::LoadCharacter("builtin:robot");
    FAIL() << "an unknown built-in must throw";
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("builtin:robot"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("builtin:figure"), std::string::npos);
  }
  const authoring::Scene scene = authoring::ParseScene(
      "characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n    keys:\n"
      "      - azimuth: 0\n        generate: lookat\n      - azimuth: 90\n        generate: lookat\n"
      "      - azimuth: 200\n        clip: Wave\n",
      "/tmp/some/dir/scene.yaml");
  ASSERT_EQ(scene.characters.size(), 1u);
  EXPECT_EQ(scene.characters[0].asset, "builtin:figure");  // not resolved against the scene's folder
  EXPECT_EQ(scene.characters[0].name, "figure");
  authoring::AnimatedCharacter figure(scene.characters[0]);
  // The key at azimuth 90 turns the head toward +X (the viewer at the figure's left).
  const anim::AnimatorFrame& out = figure.Update(Eigen::Vector3d::UnitX(), 1.0);
  const Eigen::Vector3d forward = anim::HeadForward(figure.lookat_chain(), out.model);
  EXPECT_LT(AngleDeg(forward, Eigen::Vector3d::UnitX()), 20.0);
}

// Gesture keys on the figure (anim_authoring/gesture.h): over its Idle, at each key's viewpoint
// in front, to the sides, above, below and behind, the right forearm points (or the hand
// reaches) within 15° of the viewpoint, the elbow and shoulder within their limits.
TEST(Figure, GestureKeysPointTheRightArmAtTheViewpoint) {
  RegisterBuiltinCharacters();
  EXPECT_EQ(authoring::DefaultArmChain(Figure().skeleton, authoring::ArmSide::kRight),
            (std::vector<std::string>{"RightArm", "RightForeArm", "RightHand"}));
  const anim::ArmLimits limits;
  for (const char* gesture : {"point", "reach"}) {
    double worst = 0;
    for (const auto& [azimuth, elevation] : std::vector<std::pair<double, double>>{
             {0, 0}, {35, 0}, {-35, 0}, {70, 0}, {-70, 0}, {100, 0}, {-100, 0}, {0, 30}, {40, 25}, {-40, -20}, {180, 0}}) {
      const authoring::Scene scene = authoring::ParseScene(
          "characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n    keys:\n      - {azimuth: " +
              std::to_string(azimuth) + ", elevation: " + std::to_string(elevation) + ", gesture: " + gesture +
              "}\n      - {azimuth: " + std::to_string(azimuth + 90) + ", generate: lookat}\n",
          "figure.yaml");
      authoring::AnimatedCharacter figure(scene.characters[0]);
      const authoring::KeySpec& key = scene.characters[0].keys[0];
      for (double t : {0.0, 0.37, 1.5, 2.9}) {
        const anim::AnimatorFrame& out = figure.Update(key.viewpoint, t);
        const double deg = AngleDeg(authoring::GestureDirection(figure.arm_chain(), key.gesture, out.model), key.viewpoint);
        EXPECT_LE(deg, 15.0) << gesture << " azimuth " << azimuth << " elevation " << elevation << " t " << t;
        const double elbow = authoring::ElbowBendDeg(figure.arm_chain(), out.model);
        EXPECT_GE(elbow, limits.elbow_min_deg - 0.5);
        EXPECT_LE(elbow, limits.elbow_max_deg + 0.5);
        EXPECT_LE(authoring::ShoulderConeAngleDeg(figure.character().skeleton, figure.arm_chain(), out.model),
                  limits.shoulder_cone_deg + 0.5);
        worst = std::max(worst, deg);
      }
    }
    std::printf("[gesture] builtin:figure %s: worst hand-to-viewpoint %.2f deg\n", gesture, worst);
  }
}

}  // namespace
}  // namespace arview::figure
