#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

fs::path Fox() { return testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"); }

std::string FoxScene(const std::string& keys, const std::string& extra = "") {
  return "characters:\n  - name: fox\n    asset: " + Fox().string() + "\n    scale: 0.01\n" + extra + "    keys:\n" + keys;
}

TEST(Scene, ParsesEveryField) {
  const Scene s = ParseScene(R"(characters:
  - name: fox
    asset: chars/fox.glb
    scale: 0.01
    anchor:
      position: [1, 2, 3]
      rotation_deg: [0, 90, 0]
      scale: 2
    forward: [0, 0, 1]
    up: [0, 1, 0]
    weights: {mode: local, distance: chordal, alpha: 4}
    blend: {method: dib, precision: 0.0001, max_iterations: 10}
    phase: independent
    sampling: nlerp
    lookat:
      base_clip: Survey
      chain: [a, b]
      limits: [30, 60]
    keys:
      - viewpoint: [0, 0, 2]
        clip: Survey
      - azimuth: 90
        generate: lookat
      - azimuth: 180
        elevation: 30
        pose: Walk@0.25
      - azimuth: -90
        pose: rest
)", "/scenes/s.yaml");
  ASSERT_EQ(s.characters.size(), 1u);
  const CharacterSpec& c = s.characters[0];
  EXPECT_EQ(c.asset, fs::path("/scenes/chars/fox.glb"));
  EXPECT_EQ(c.where, "/scenes/s.yaml:2");
  EXPECT_DOUBLE_EQ(c.scale, 0.01);
  EXPECT_LT((c.anchor.position - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.anchor.scale, 2);
  EXPECT_EQ(c.weights.mode, anim::WeightingMode::kLocalSupport);
  EXPECT_EQ(c.weights.distance, anim::DistanceKind::kChordal);
  EXPECT_DOUBLE_EQ(c.weights.alpha, 4);
  EXPECT_EQ(c.blend, anim::BlendMethod::kDib);
  EXPECT_DOUBLE_EQ(c.dib.precision, 1e-4);
  EXPECT_EQ(c.dib.max_iterations, 10);
  EXPECT_EQ(c.phase, anim::PhaseMode::kIndependent);
  EXPECT_TRUE(c.nlerp_sampling);
  EXPECT_EQ(c.lookat.chain, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(c.keys.size(), 4u);
  EXPECT_LT((c.keys[0].viewpoint - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((c.keys[1].viewpoint - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_EQ(c.keys[1].source, KeySpec::Source::kLookAt);
  EXPECT_EQ(c.keys[2].source, KeySpec::Source::kStaticPose);
  EXPECT_EQ(c.keys[2].clip, "Walk");
  EXPECT_DOUBLE_EQ(c.keys[2].pose_time, 0.25);
  EXPECT_EQ(c.keys[3].source, KeySpec::Source::kRestPose);
  // Anchor: model → map, and the camera direction back in the character's frame.
  const Eigen::Matrix4d m = c.placement().ModelToMap();
  const Eigen::Vector4d p = m * Eigen::Vector4d(0, 0, 100, 1);  // 1 m in front, scaled by 2
  EXPECT_LT((p.head<3>() - Eigen::Vector3d(3, 2, 3)).norm(), 1e-9);
  EXPECT_LT((c.placement().ViewpointFromCamera(Eigen::Vector3d(5, 2, 3)) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
}

void ExpectSceneError(const std::string& text, const std::string& message) {
  try {
    ParseScene(text, "bad.yaml");
    FAIL() << "no error";
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(Scene, ParseErrors) {
  ExpectSceneError("characters:\n  - asset: a.glb\n    keys:\n      - viewpoint: [0, 0, 0]\n        clip: x\n",
                   "bad.yaml:4: key viewpoint (0, 0, 0) is 0 long, below 1e-09: too short to give a direction");
  ExpectSceneError("characters:\n  - asset: a.glb\n    keys:\n      - azimuth: 0\n", "bad.yaml:4: a key needs exactly one");
  ExpectSceneError("characters:\n  - asset: a.glb\n    colour: red\n    keys:\n      - azimuth: 0\n        clip: x\n",
                   "bad.yaml:3: unknown key 'colour'");
  ExpectSceneError("characters:\n  - asset: a.glb\n    blend: {method: slerp}\n    keys:\n      - azimuth: 0\n        clip: x\n",
                   "bad.yaml:3: blend.method: 'slerp' is not one of dlb | dib");
  ExpectSceneError("characters:\n  - asset: a.glb\n    scale: big\n    keys:\n      - azimuth: 0\n        clip: x\n",
                   "bad.yaml:3: scale: expected a number, got 'big'");
  ExpectSceneError("characters:\n  - keys:\n      - azimuth: 0\n        clip: x\n", "bad.yaml:2: a character needs 'asset");
  ExpectSceneError("characters: []\n", "bad.yaml: a scene needs a non-empty 'characters:' list");
  EXPECT_THROW(LoadScene("/nonexistent/scene.yaml"), anim::Error);
}

TEST(Scene, GazeSection) {
  const std::string keys = "    keys:\n      - azimuth: 0\n        clip: x\n";
  const Scene defaults = ParseScene("characters:\n  - asset: a.glb\n" + keys, "g.yaml");
  EXPECT_TRUE(defaults.characters[0].gaze.enabled);
  EXPECT_EQ(defaults.characters[0].gaze.options.mode, anim::GazeMode::kListening);
  const Scene s = ParseScene("characters:\n  - asset: a.glb\n    gaze: {enabled: false, mode: talking, blink_rate: 12, "
                             "eye_range: {sideways: 30, up: 15, down: 20}, seed: 9}\n" + keys,
                             "g.yaml");
  const GazeSpec& g = s.characters[0].gaze;
  EXPECT_FALSE(g.enabled);
  EXPECT_EQ(g.options.mode, anim::GazeMode::kTalking);
  EXPECT_EQ(g.options.blink_rate_per_min, 12);
  EXPECT_EQ(g.options.range.sideways_deg, 30);
  EXPECT_EQ(g.options.range.up_deg, 15);
  EXPECT_EQ(g.options.range.down_deg, 20);
  EXPECT_EQ(g.options.seed, 9u);
  ExpectSceneError("characters:\n  - asset: a.glb\n    gaze: {mode: dreaming}\n" + keys,
                   "bad.yaml:3: gaze.mode: 'dreaming' is not one of");
  ExpectSceneError("characters:\n  - asset: a.glb\n    gaze: {blink_rate: 0}\n" + keys, "bad.yaml:3: gaze.blink_rate");
  ExpectSceneError("characters:\n  - asset: a.glb\n    gaze: {eye_range: {up: 90}}\n" + keys, "bad.yaml:3: gaze.eye_range.up");
  ExpectSceneError("characters:\n  - asset: a.glb\n    gaze: {wink: 1}\n" + keys, "bad.yaml:3: unknown key 'wink'");
}

TEST(Scene, ParseViewpoint) {
  EXPECT_LT((ParseViewpoint("0,0,2") - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((ParseViewpoint(" 1, 0 ,0") - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_THROW(ParseViewpoint("1,2"), anim::Error);
  EXPECT_THROW(ParseViewpoint("1,2,3,4"), anim::Error);
  // Issue 17: the norm of (1e308, 1e308, 1e308) overflowed and the direction became (0, 0, 0).
  // Issue 41: such a vector is refused, saying how long it is and the limit (anim::UnitDirection).
  EXPECT_LT((ParseViewpoint("1e11,1e11,1e10") - Eigen::Vector3d(10, 10, 1).normalized()).norm(), 1e-12);
  EXPECT_THROW(ParseViewpoint("1,x,3"), anim::Error);
  EXPECT_THROW(ParseViewpoint("1,nan,3"), anim::Error);
  auto error_of = [](const std::string& text) -> std::string {
    try {
      ParseViewpoint(text, "--viewpoint");
    } catch (const anim::Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of("0,0,0"), "--viewpoint: the viewpoint (0, 0, 0) is 0 long, below 1e-09: too short to give a direction");
  // 5e-324 was refused as "expected three numbers": stod refuses a denormal as out of range.
  EXPECT_EQ(error_of("5e-324,0,0"),
            "--viewpoint: the viewpoint (4.94066e-324, 0, 0) is 4.94e-324 long, below 1e-09: too short to give a direction");
  EXPECT_EQ(error_of("1e308,1e308,1e308"),
            "--viewpoint: the viewpoint (1e+308, 1e+308, 1e+308) is 1.73e+308 long, beyond 1e+12 (a direction such as "
            "[0, 0, 1] is expected)");
  EXPECT_EQ(error_of("1e400,0,0"),
            "--viewpoint: '1e400' in \"1e400,0,0\" is not a finite number (expected three numbers \"x,y,z\")");
}

// Issue 41: a key viewpoint 1e300 long was refused as "zero length" and pointed at the
// character's line; it is refused at the key's own line, saying how long it is.
TEST(Scene, AKeyViewpointTooLongOrTooShortIsRefusedAtItsLine) {
  ExpectSceneError("characters:\n  - asset: a.glb\n    keys:\n      - azimuth: 0\n        clip: x\n"
                   "      - viewpoint: [1e300, 1e300, 1e300]\n        clip: x\n",
                   "bad.yaml:6: key viewpoint (1e+300, 1e+300, 1e+300) is 1.73e+300 long, beyond 1e+12");
  ExpectSceneError("characters:\n  - asset: a.glb\n    forward: [0, 0, 1e-300]\n    keys:\n      - azimuth: 0\n"
                   "        clip: x\n",
                   "bad.yaml:3: forward (0, 0, 1e-300) is 1e-300 long, below 1e-09: too short to give a direction");
}

TEST(Scene, MissingClipIsAnError) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const Scene s = ParseScene(FoxScene("      - azimuth: 0\n        clip: Survey\n      - azimuth: 90\n        clip: Jump\n"),
                             "fox.yaml");
  try {
    AnimatedCharacter c(s.characters[0]);
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("fox.yaml:8: clip 'Jump' does not exist"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Survey, Walk, Run"), std::string::npos) << e.what();
  }
}

TEST(Scene, MissingAssetIsAnError) {
  const Scene s = ParseScene("characters:\n  - asset: nowhere.glb\n    keys:\n      - azimuth: 0\n        pose: rest\n",
                             "/tmp/x/s.yaml");
  try {
    AnimatedCharacter c(s.characters[0]);
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/tmp/x/nowhere.glb: no such file"), std::string::npos) << e.what();
  }
}

TEST(Scene, RuntimeOnAKeyPlaysThatClip) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  for (const char* method : {"dlb", "dib"}) {
    const Scene s = ParseScene(
        FoxScene("      - azimuth: 0\n        clip: Survey\n      - azimuth: 120\n        clip: Walk\n"
                 "      - azimuth: 240\n        pose: rest\n",
                 std::string("    phase: independent\n    blend: {method: ") + method + "}\n"),
        "fox.yaml");
    AnimatedCharacter fox(s.characters[0]);
    const anim::Character& c = fox.character();
    const anim::AnimatorFrame& out = fox.Update(anim::DirectionFromAzimuthElevation(120, 0), 0.3);
    EXPECT_DOUBLE_EQ(out.key_weights[1], 1.0);
    anim::LocalPose walk(c.skeleton.size());
    ASSERT_TRUE((anim::SamplingJob{&c.skeleton, c.FindClip("Walk"), 0.3, true, &walk}.Run()));
    std::vector<Eigen::Matrix4d> model(c.skeleton.size());
    ASSERT_TRUE((anim::LocalToModelJob{&c.skeleton, &walk, model}.Run()));
    for (int j = 0; j < c.skeleton.size(); ++j) EXPECT_LT((out.model[j] - model[j]).norm(), 1e-6) << j;
    EXPECT_TRUE(out.converged);
    // Between keys every joint is a proper blend, and DIB converges.
    const anim::AnimatorFrame& mid = fox.Update(anim::DirectionFromAzimuthElevation(60, 20), 1.0);
    EXPECT_TRUE(mid.converged);
    for (const auto& m : mid.skinning_matrices) EXPECT_TRUE(m.allFinite());
    EXPECT_TRUE(anim::RigidSkinning(mid.skinning_matrices));
  }
}

TEST(Scene, SharedPhaseStretchesKeyClips) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const Scene s = ParseScene(FoxScene("      - azimuth: 0\n        clip: Walk\n      - azimuth: 180\n        clip: Run\n"),
                             "fox.yaml");
  AnimatedCharacter fox(s.characters[0]);
  const anim::Character& c = fox.character();
  const double walk = c.FindClip("Walk")->duration, run = c.FindClip("Run")->duration;
  const double period = 0.5 * (walk + run);
  // A quarter of the shared period plays a quarter of the Run clip.
  const anim::AnimatorFrame& out = fox.Update(anim::DirectionFromAzimuthElevation(180, 0), 0.25 * period);
  anim::LocalPose expect(c.skeleton.size());
  ASSERT_TRUE((anim::SamplingJob{&c.skeleton, c.FindClip("Run"), 0.25 * run, true, &expect}.Run()));
  std::vector<Eigen::Matrix4d> model(c.skeleton.size());
  ASSERT_TRUE((anim::LocalToModelJob{&c.skeleton, &expect, model}.Run()));
  for (int j = 0; j < c.skeleton.size(); ++j) EXPECT_LT((out.model[j] - model[j]).norm(), 1e-6) << j;
}

}  // namespace
}  // namespace arview::authoring
