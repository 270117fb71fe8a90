// Gesture keys (gesture.h) on real humanoid rigs: at each key's viewpoint the blended character's
// hand points (forearm) or reaches (shoulder → hand) along the viewpoint, within the joint limits;
// a direction the shoulder cannot reach is clamped toward it, not flipped; a rig without arms
// is refused with a clear message.

#include "anim_authoring/character_builder.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/scene.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

const char* kBcn = "/usr/share/assimp/models/X/BCN_Epileptic.X";

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

struct KeyAt {
  double azimuth, elevation;
};

// In front and to both sides, level, above and below, and behind (the body turns).
const std::vector<KeyAt> kSpread = {{0, 0},    {35, 0},  {-35, 0}, {70, 0},   {-70, 0}, {100, 0},
                                    {-100, 0}, {0, 30},  {40, 25}, {-40, -20}, {0, -25}, {180, 0}};

struct GestureStats {
  double worst_deg = 0, worst_elbow_low = 180, worst_elbow_high = 0, worst_cone = 0;
  int samples = 0;
};

// One scene per key (a key at its own viewpoint has weight 1): the blended pose at that
// viewpoint, at several times of the base clip.
GestureStats Measure(const std::string& asset, const std::string& gesture, const std::string& extra = "") {
  GestureStats st;
  for (const KeyAt& k : kSpread) {
    const std::string text = "characters:\n  - asset: " + asset + "\n" + extra +
                             "    keys:\n      - {azimuth: " + std::to_string(k.azimuth) +
                             ", elevation: " + std::to_string(k.elevation) + ", gesture: " + gesture +
                             "}\n      - {azimuth: " + std::to_string(k.azimuth + 90) + ", generate: lookat}\n";
    const Scene scene = ParseScene(text, "gesture.yaml");
    AnimatedCharacter ch(scene.characters[0]);
    const anim::ArmChain& arm = ch.arm_chain();
    const Gesture g = scene.characters[0].keys[0].gesture;
    const Eigen::Vector3d v = scene.characters[0].keys[0].viewpoint;
    // On the key clip's 30 Hz samples and between them (interpolated).
    for (double t : {0.0, 0.4, 0.37, 1.1, 1.23, 1.9}) {
      const anim::AnimatorFrame& out = ch.Update(v, t);
      EXPECT_NEAR(out.key_weights[0], 1.0, 1e-9);
      const double deg = AngleDeg(GestureDirection(arm, g, out.model), v);
      const double elbow = ElbowBendDeg(arm, out.model);
      const double cone = ShoulderConeAngleDeg(ch.character().skeleton, arm, out.model);
      EXPECT_LE(deg, 15.0) << asset << " " << gesture << " azimuth " << k.azimuth << " elevation " << k.elevation;
      st.worst_deg = std::max(st.worst_deg, deg);
      st.worst_elbow_low = std::min(st.worst_elbow_low, elbow);
      st.worst_elbow_high = std::max(st.worst_elbow_high, elbow);
      st.worst_cone = std::max(st.worst_cone, cone);
      ++st.samples;
    }
  }
  std::printf("[gesture] %s %s: %d samples, worst hand-to-viewpoint %.2f deg, elbow bend %.1f..%.1f deg, "
              "shoulder cone angle <= %.1f deg\n",
              fs::path(asset).filename().c_str(), gesture.c_str(), st.samples, st.worst_deg, st.worst_elbow_low,
              st.worst_elbow_high, st.worst_cone);
  ::testing::Test::RecordProperty("worst_deg_" + gesture, std::to_string(st.worst_deg));
  return st;
}

// Joint limits hold exactly on the key clip's samples; between them rotation keys are slerped,
// which may move a joint past a limit by a fraction of a degree.
constexpr double kBetweenSamplesDeg = 0.5;

void CheckCharacter(const std::string& asset, const std::string& extra = "") {
  const anim::ArmLimits defaults;
  for (const char* g : {"point", "reach"}) {
    const GestureStats st = Measure(asset, g, extra);
    EXPECT_GE(st.worst_elbow_low, defaults.elbow_min_deg - kBetweenSamplesDeg) << g;
    EXPECT_LE(st.worst_elbow_high, defaults.elbow_max_deg + kBetweenSamplesDeg) << g;
    EXPECT_LE(st.worst_cone, defaults.shoulder_cone_deg + kBetweenSamplesDeg) << g;
  }
}

TEST(Gesture, BcnEpileptic) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  CheckCharacter(kBcn);
}

TEST(Gesture, CesiumMan) {
  const fs::path man = testing::SharedData("characters/CesiumMan.glb");
  ARVIEW_REQUIRE_DATA_PATH(man, "../shared/data");
  CheckCharacter(man.string());
}

// Between keys: 8 point keys around the horizon, viewpoints 10°, 22.5° and 35° past each key,
// at 4 times: within 15° as the gaze is (the goal is stated at the keys' viewpoints).
void MeasureBetweenKeys(const std::string& asset, const std::string& mode) {
  std::string text = "characters:\n  - asset: " + asset + "\n    weights: {mode: " + mode + "}\n    keys:\n";
  for (int k = 0; k < 8; ++k) text += "      - {azimuth: " + std::to_string(45 * k) + ", gesture: point}\n";
  const Scene scene = ParseScene(text, "ring.yaml");
  AnimatedCharacter ch(scene.characters[0]);
  std::vector<double> angles;
  for (int k = 0; k < 8; ++k)
    for (double offset : {10.0, 22.5, 35.0})
      for (double t : {0.0, 0.37, 1.23, 1.9}) {
        const Eigen::Vector3d v = anim::DirectionFromAzimuthElevation(45 * k + offset, 0);
        angles.push_back(AngleDeg(GestureDirection(ch.arm_chain(), Gesture::kPoint, ch.Update(v, t).model), v));
      }
  std::sort(angles.begin(), angles.end());
  const double median = angles[angles.size() / 2], worst = angles.back();
  std::printf("[gesture] %s ring of 8 point keys, %s weights, between keys: median %.2f deg, max %.2f deg (%zu samples)\n",
              fs::path(asset).filename().c_str(), mode.c_str(), median, worst, angles.size());
  EXPECT_LE(worst, 15.0) << asset << " " << mode;
}

TEST(Gesture, BetweenKeysOnARing) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  for (const char* mode : {"inverse-distance", "local"}) MeasureBetweenKeys(kBcn, mode);
  const fs::path man = testing::SharedData("characters/CesiumMan.glb");
  ARVIEW_REQUIRE_DATA_PATH(man, "../shared/data");
  for (const char* mode : {"inverse-distance", "local"}) MeasureBetweenKeys(man.string(), mode);
}

TEST(Gesture, DefaultArmChainsByName) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  const anim::Character bcn = LoadCharacter(kBcn);
  EXPECT_EQ(DefaultArmChain(bcn.skeleton, ArmSide::kRight),
            (std::vector<std::string>{"B_UpperArm_Right", "B_ForeArm_Right", "B_Hand_Right"}));
  EXPECT_EQ(DefaultArmChain(bcn.skeleton, ArmSide::kLeft),
            (std::vector<std::string>{"B_UpperArm_Left", "B_ForeArm_Left", "B_Hand_Left"}));
  // Mixamo names, with and without the prefix, and CMU's wrist below the radius.
  for (const std::string prefix : {"", "mixamorig:"}) {
    anim::Skeleton sk;
    for (const std::string n : {"Hips", "Spine", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
                                "RightHandIndex1"}) {
      sk.parents.push_back(sk.names.empty() ? -1 : static_cast<int>(sk.names.size()) - 1);
      sk.names.push_back(prefix + n);
    }
    EXPECT_EQ(DefaultArmChain(sk, ArmSide::kRight),
              (std::vector<std::string>{prefix + "RightArm", prefix + "RightForeArm", prefix + "RightHand"}));
    EXPECT_TRUE(DefaultArmChain(sk, ArmSide::kLeft).empty());
  }
  anim::Skeleton cmu;
  for (const std::string n : {"hip", "lowerback", "rclavicle", "rhumerus", "rradius", "rwrist", "rhand"}) {
    cmu.parents.push_back(cmu.names.empty() ? -1 : static_cast<int>(cmu.names.size()) - 1);
    cmu.names.push_back(n);
  }
  EXPECT_EQ(DefaultArmChain(cmu, ArmSide::kRight), (std::vector<std::string>{"rhumerus", "rradius", "rwrist"}));
}

TEST(Gesture, CesiumManArmChainByName) {
  const fs::path man = testing::SharedData("characters/CesiumMan.glb");
  ARVIEW_REQUIRE_DATA_PATH(man, "../shared/data");
  const anim::Character c = LoadCharacter(man);
  EXPECT_EQ(DefaultArmChain(c.skeleton, ArmSide::kRight),
            (std::vector<std::string>{"Skeleton_arm_joint_R", "Skeleton_arm_joint_R__2_", "Skeleton_arm_joint_R__3_"}));
  EXPECT_EQ(DefaultArmChain(c.skeleton, ArmSide::kLeft),
            (std::vector<std::string>{"Skeleton_arm_joint_L__4_", "Skeleton_arm_joint_L__3_", "Skeleton_arm_joint_L__2_"}));
}

// Without the look-at chain the body does not turn: a viewpoint behind lies outside the shoulder
// cone and is moved onto its boundary toward the target, never to the other side.
TEST(Gesture, BehindIsClampedNotFlipped) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  const anim::Character bcn = LoadCharacter(kBcn);
  const anim::Skeleton& sk = bcn.skeleton;
  const Eigen::Vector3d forward = Eigen::Vector3d::UnitZ(), up = Eigen::Vector3d::UnitY();
  for (ArmSide side : {ArmSide::kRight, ArmSide::kLeft}) {
    const anim::ArmChain arm = MakeArmChain(sk, {}, side, {}, forward, up);
    // The arm's side, from where its shoulder is at rest.
    std::vector<Eigen::Matrix4d> model(sk.size());
    anim::LocalPose rest = anim::LocalPose::Rest(sk);
    anim::MustRun(anim::LocalToModelJob{&sk, &rest, model}, "test");
    const double out = model[arm.upper](0, 3) > 0 ? 1 : -1;
    for (double behind_side : {0.3, -0.3, 0.0}) {
      const Eigen::Vector3d target = Eigen::Vector3d(behind_side * out, 0.1, -1).normalized();
      const anim::Clip clip = GenerateGestureClip(sk, nullptr, nullptr, arm, Gesture::kPoint, target);
      anim::LocalPose pose(sk.size());
      anim::MustRun(anim::SamplingJob{&sk, &clip, 0.0, false, &pose}, "test");
      anim::MustRun(anim::LocalToModelJob{&sk, &pose, model}, "test");
      EXPECT_LE(ShoulderConeAngleDeg(sk, arm, model), arm.limits.shoulder_cone_deg + 0.01);
      const Eigen::Vector3d d = GestureDirection(arm, Gesture::kPoint, model);
      // Clamped: still pointing backward-ish and out to the arm's side, not forward or across.
      EXPECT_GT(d.x() * out, 0.3) << ToString(side) << " " << behind_side;
      EXPECT_LT(d.z(), 0.2) << ToString(side) << " " << behind_side;
      // Toward the target: closer to it than the cone's axis is.
      const Eigen::Vector3d axis = (forward + out * Eigen::Vector3d::UnitX()).normalized();
      EXPECT_LT(AngleDeg(d, target), AngleDeg(axis, target)) << ToString(side) << " " << behind_side;
    }
  }
}

TEST(Gesture, ElbowRangeIsKept) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  const std::string extra = "    gesture: {arm: left, elbow: [25, 60], bend: {point: 5, reach: 90}}\n";
  for (const char* g : {"point", "reach"}) {
    const GestureStats st = Measure(kBcn, g, extra);
    EXPECT_GE(st.worst_elbow_low, 25 - kBetweenSamplesDeg) << g;
    EXPECT_LE(st.worst_elbow_high, 60 + kBetweenSamplesDeg) << g;
  }
}

TEST(Gesture, NoArmChainIsAnError) {
  anim::Skeleton sk;
  sk.names = {"Hips", "Spine", "Neck", "Head"};
  sk.parents = {-1, 0, 1, 2};
  sk.rest.resize(4);
  sk.inverse_bind.assign(4, Eigen::Matrix4d::Identity());
  try {
    MakeArmChain(sk, {}, ArmSide::kRight, {}, Eigen::Vector3d::UnitZ());
    ADD_FAILURE() << "expected an error";
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("right arm: no chain found by name"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gesture.chain"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MakeArmChain(sk, {"Spine", "Head", "Neck"}, ArmSide::kRight, {}, Eigen::Vector3d::UnitZ()), anim::Error);
}

TEST(Gesture, SceneRefusesUnknownValuesWithTheLine) {
  auto error_of = [](const std::string& text) {
    try {
      ParseScene(text, "g.yaml");
    } catch (const anim::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = "characters:\n  - asset: x.glb\n";
  EXPECT_NE(error_of(head + "    keys:\n      - azimuth: 0\n        gesture: wave\n").find("g.yaml:5"), std::string::npos);
  EXPECT_NE(error_of(head + "    keys:\n      - azimuth: 0\n        gesture: wave\n").find("'wave' is not one of point | reach"),
            std::string::npos);
  EXPECT_NE(error_of(head + "    keys:\n      - {azimuth: 0, gesture: point, clip: Idle}\n").find("exactly one of"),
            std::string::npos);
  EXPECT_NE(error_of(head + "    gesture: {arm: middle}\n    keys:\n      - {azimuth: 0, gesture: point}\n").find("g.yaml:3"),
            std::string::npos);
  EXPECT_NE(error_of(head + "    gesture: {elbow: [90, 10]}\n    keys:\n      - {azimuth: 0, gesture: point}\n")
                .find("gesture.elbow"),
            std::string::npos);
  EXPECT_NE(error_of(head + "    gesture: {chain: [a, b]}\n    keys:\n      - {azimuth: 0, gesture: point}\n")
                .find("gesture.chain"),
            std::string::npos);
  const Scene ok = ParseScene(head + "    gesture: {arm: left}\n    keys:\n      - {azimuth: 0, gesture: reach}\n"
                                     "      - {azimuth: 90, generate: lookat, gesture: point}\n",
                              "g.yaml");
  EXPECT_EQ(ok.characters[0].gesture.side, ArmSide::kLeft);
  EXPECT_EQ(ok.characters[0].keys[0].source, KeySpec::Source::kLookAt);
  EXPECT_EQ(ok.characters[0].keys[0].gesture, Gesture::kReach);
  EXPECT_EQ(ok.characters[0].keys[1].gesture, Gesture::kPoint);
}

TEST(Gesture, MissingChainJointInTheSceneIsAnError) {
  ARVIEW_REQUIRE_DATA_PATH(fs::path(kBcn), "Debian package assimp-testmodels");
  const Scene scene = ParseScene(std::string("characters:\n  - asset: ") + kBcn +
                                     "\n    gesture: {chain: [B_UpperArm_Right, B_ForeArm_Right, RightHand]}\n"
                                     "    keys:\n      - {azimuth: 0, gesture: point}\n",
                                 "g.yaml");
  try {
    AnimatedCharacter ch(scene.characters[0]);
    ADD_FAILURE() << "expected an error";
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("g.yaml:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no joint 'RightHand'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arview::authoring
