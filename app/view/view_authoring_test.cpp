// Key authoring: the key list's history, and the scene file edited in place.

#include <gtest/gtest.h>

#include <cmath>

#include "anim_authoring/scene.h"
#include "app/view/view_authoring.h"

namespace arview::app {
namespace {

const char* kScene = R"(# my scene: keep this comment
characters:
  - name: first
    asset: a.glb
    keys:
      # the front key
      - azimuth: 0
        clip: Survey   # looks around
      - viewpoint: [1, 0, 0]
        generate: lookat
    phase: shared
  - name: second
    asset: b.glb
    keys:
    - azimuth: 180
      pose: rest
)";

authoring::KeySpec Key(double azimuth, authoring::KeySpec::Source source, const std::string& clip = "", double t = 0) {
  authoring::KeySpec k;
  k.viewpoint = anim::DirectionFromAzimuthElevation(azimuth, 0);
  k.source = source;
  k.clip = clip;
  k.pose_time = t;
  return k;
}

TEST(KeyEditor, AddRemoveUndoAndDirty) {
  KeyEditor e({Key(0, authoring::KeySpec::Source::kClip, "Survey"), Key(90, authoring::KeySpec::Source::kLookAt)});
  EXPECT_FALSE(e.dirty());
  EXPECT_FALSE(e.can_undo());
  e.Add(Key(45, authoring::KeySpec::Source::kRestPose));
  EXPECT_TRUE(e.dirty());
  EXPECT_EQ(e.keys().size(), 3u);
  EXPECT_EQ(e.FileOrigins(), (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(e.Nearest(anim::DirectionFromAzimuthElevation(80, 10)), 1);
  e.Remove(0);
  EXPECT_EQ(e.FileOrigins(), (std::vector<int>{1, -1}));
  EXPECT_TRUE(e.Undo());
  EXPECT_EQ(e.keys().size(), 3u);
  EXPECT_TRUE(e.Undo());
  EXPECT_EQ(e.keys().size(), 2u);
  EXPECT_FALSE(e.dirty());  // back to what the file holds
  EXPECT_FALSE(e.Undo());
  e.Add(Key(10, authoring::KeySpec::Source::kLookAt));
  e.MarkSaved();
  EXPECT_FALSE(e.dirty());
  EXPECT_EQ(e.FileOrigins(), (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(e.Undo());  // undo still works after a save, and the file then differs
  EXPECT_TRUE(e.dirty());
}

TEST(KeyEditor, TheLastKeyStays) {
  KeyEditor e({Key(0, authoring::KeySpec::Source::kLookAt)});
  EXPECT_THROW(e.Remove(0), std::runtime_error);
  EXPECT_EQ(e.keys().size(), 1u);
}

TEST(SpliceKeys, KeepsEverythingButTheEditedKeys) {
  const authoring::Scene scene = authoring::ParseScene(kScene, "s.yaml");
  std::vector<authoring::KeySpec> keys = scene.characters[0].keys;
  keys.erase(keys.begin());                                          // the front key goes
  keys.push_back(Key(-37.25, authoring::KeySpec::Source::kStaticPose, "Walk", 0.25));  // a new one comes
  const std::string text = SpliceKeys(kScene, scene, 0, keys, {1, -1});
  EXPECT_NE(text.find("# my scene: keep this comment"), std::string::npos);
  EXPECT_EQ(text.find("looks around"), std::string::npos);  // its comment went with it
  EXPECT_NE(text.find("      - viewpoint: [1, 0, 0]\n        generate: lookat\n"), std::string::npos) << text;
  EXPECT_NE(text.find("      - azimuth: -37.25\n        elevation: 0\n        pose: \"Walk@0.25\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    phase: shared\n  - name: second"), std::string::npos) << text;
  const authoring::Scene reread = ValidateSceneText(text, "s.yaml", 0, keys);
  EXPECT_EQ(reread.characters[1].keys.size(), 1u);
  EXPECT_EQ(reread.characters[0].keys[1].source, authoring::KeySpec::Source::kStaticPose);
  EXPECT_DOUBLE_EQ(reread.characters[0].keys[1].pose_time, 0.25);
}

TEST(SpliceKeys, AGestureKeyKeepsItsGesture) {
  const authoring::Scene scene = authoring::ParseScene(kScene, "s.yaml");
  std::vector<authoring::KeySpec> keys = scene.characters[0].keys;
  authoring::KeySpec pointing = Key(30, authoring::KeySpec::Source::kLookAt);
  pointing.gesture = authoring::Gesture::kPoint;
  keys.push_back(pointing);  // an edit elsewhere must not turn it into a plain look-at key
  const std::string text = SpliceKeys(kScene, scene, 0, keys, {0, 1, -1});
  EXPECT_NE(text.find("        elevation: 0\n        gesture: point\n"), std::string::npos) << text;
  const authoring::Scene reread = ValidateSceneText(text, "s.yaml", 0, keys);
  EXPECT_EQ(reread.characters[0].keys.back().gesture, authoring::Gesture::kPoint);
}

TEST(SpliceKeys, SecondCharacterWithItemsAtTheKeysColumn) {
  const authoring::Scene scene = authoring::ParseScene(kScene, "s.yaml");
  std::vector<authoring::KeySpec> keys = scene.characters[1].keys;
  keys.push_back(Key(12.5, authoring::KeySpec::Source::kClip, "Run"));
  const std::string text = SpliceKeys(kScene, scene, 1, keys, {0, -1});
  EXPECT_NE(text.find("    - azimuth: 180\n      pose: rest\n    - azimuth: 12.5\n      elevation: 0\n      clip: \"Run\"\n"),
            std::string::npos)
      << text;
  ValidateSceneText(text, "s.yaml", 1, keys);
  EXPECT_EQ(text.substr(0, text.find("  - name: second")), std::string(kScene).substr(0, std::string(kScene).find("  - name: second")));
}

TEST(SpliceKeys, RefusesFlowStyleKeysAndMismatches) {
  const std::string flow = "characters:\n  - name: f\n    asset: a.glb\n    keys: [{azimuth: 0, clip: A}]\n";
  const authoring::Scene scene = authoring::ParseScene(flow, "f.yaml");
  try {
    SpliceKeys(flow, scene, 0, scene.characters[0].keys, {0});
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("f.yaml: cannot write the keys of character 'f': they are written in flow style"),
              std::string::npos)
        << e.what();
  }
  const authoring::Scene good = authoring::ParseScene(kScene, "s.yaml");
  std::vector<authoring::KeySpec> other = good.characters[0].keys;
  other[0].viewpoint = anim::DirectionFromAzimuthElevation(1, 0);
  EXPECT_THROW(ValidateSceneText(kScene, "s.yaml", 0, other), std::runtime_error);
}

TEST(MakeKey, RoundsToHundredthsOfADegreeAndFreezesPosesInTheClip) {
  anim::Character asset;
  asset.clips.push_back({"Walk", 0.708, 1000, {}, {}});
  authoring::CharacterSpec spec;
  const Eigen::Vector3d v = anim::DirectionFromAzimuthElevation(33.333333, 12.345678);
  const authoring::KeySpec k = MakeKey(v, {authoring::KeySpec::Source::kStaticPose, "Walk", ""}, asset, spec, 2.0);
  const Eigen::Vector2d ae = AzimuthElevation(k.viewpoint, spec.forward, spec.up);
  EXPECT_NEAR(ae.x(), 33.33, 1e-9);
  EXPECT_NEAR(ae.y(), 12.35, 1e-9);
  EXPECT_NEAR(k.pose_time, std::round(std::fmod(2.0, 0.708) * 100) / 100, 1e-12);
  const std::vector<KeyChoice> choices = KeyChoices(asset);
  ASSERT_EQ(choices.size(), 4u);
  EXPECT_EQ(choices[0].label, "clip Walk");
  EXPECT_EQ(choices[1].label, "generate lookat");
  EXPECT_EQ(choices[2].label, "pose rest");
  EXPECT_EQ(choices[3].label, "pose Walk@now");
}

}  // namespace
}  // namespace arview::app
