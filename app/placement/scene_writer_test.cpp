#include "app/placement/scene_writer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "anim_authoring/scene.h"

namespace arview::app {
namespace {

ScenePlacement Placed() {
  ScenePlacement c;
  c.name = "fox";
  c.asset = "/data/odd: name # here/Fox \"v2\".glb";  // quotes, ": " and " #" must survive
  c.anchor.position = Eigen::Vector3d(0.123456789, -2.5, 1e-7);
  c.anchor.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.anchor.scale = 0.0123;
  c.key_count = 6;
  c.key_elevation_deg = 12.5;
  c.base_clip = "Survey";
  c.comment = "two\nlines";
  return c;
}

TEST(SceneWriter, WritesWhatTheSceneReaderReadsBack) {
  const ScenePlacement c = Placed();
  const std::string text = SceneYaml(c);
  const authoring::Scene s = authoring::ParseScene(text, "/tmp/placed.yaml");
  ASSERT_EQ(s.characters.size(), 1u);
  const authoring::CharacterSpec& spec = s.characters[0];
  EXPECT_EQ(spec.name, "fox");
  EXPECT_EQ(spec.asset, std::filesystem::path(c.asset));
  EXPECT_LT((spec.anchor.position - c.anchor.position).norm(), 1e-9);
  EXPECT_LT(spec.anchor.rotation.angularDistance(c.anchor.rotation), 1e-8);
  EXPECT_NEAR(spec.anchor.scale, 0.0123, 1e-12);
  EXPECT_EQ(spec.lookat.base_clip, "Survey");
  ASSERT_EQ(spec.keys.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(spec.keys[k].source, authoring::KeySpec::Source::kLookAt);
    EXPECT_NEAR(std::asin(spec.keys[k].viewpoint.y()) * 180 / M_PI, 12.5, 1e-9);
  }
  // The comment stays one comment line.
  EXPECT_EQ(text.rfind("# two lines\n", 0), 0u) << text;
}

TEST(SceneWriter, BehaviourBecomesAnIdleSectionAndASchedule) {
  ScenePlacement c = Placed();
  c.behaviour.idle_clips = {"Survey", "Walk"};
  c.behaviour.idle_seed = 7;
  c.behaviour.greet_clip = "Run";
  c.behaviour.greet_within = 1.5;
  c.behaviour.front_gesture = "point";  // keys at 0, 60 and 300 degrees (within 50 of the front)
  const authoring::Scene s = authoring::ParseScene(SceneYaml(c), "/tmp/placed.yaml");
  const authoring::CharacterSpec& spec = s.characters[0];
  ASSERT_TRUE(spec.idle.given);
  EXPECT_EQ(spec.idle.clips, (std::vector<std::string>{"Survey", "Walk"}));
  EXPECT_EQ(spec.idle.seed, 7u);
  ASSERT_TRUE(spec.schedule.given);
  EXPECT_EQ(spec.schedule.view_action, "view");
  EXPECT_DOUBLE_EQ(spec.schedule.hold_seconds, 0.5);
  ASSERT_EQ(spec.schedule.actions.size(), 3u);
  const authoring::ActionSpec& idle = spec.schedule.actions[0];
  EXPECT_EQ(idle.object.kind, authoring::ObjectSpec::Kind::kIdle);
  const authoring::ActionSpec& view = spec.schedule.actions[1];
  EXPECT_EQ(view.object.kind, authoring::ObjectSpec::Kind::kViewAdaptive);
  EXPECT_EQ(view.layer, 1);
  ASSERT_EQ(view.masks.size(), 1u);
  EXPECT_EQ(view.masks[0].default_rotation, 0);
  ASSERT_EQ(view.masks[0].scopes.size(), 4u);
  EXPECT_EQ(view.masks[0].scopes[0].name, "root");
  EXPECT_EQ(view.masks[0].scopes[0].rotation, 1);
  EXPECT_EQ(view.masks[0].scopes[0].translation, 0);
  EXPECT_EQ(view.masks[0].scopes[1].name, "torso");
  const authoring::ActionSpec& greet = spec.schedule.actions[2];
  EXPECT_EQ(greet.object.clip, "Run");
  EXPECT_TRUE(greet.has_trigger);
  EXPECT_DOUBLE_EQ(greet.trigger_near, 1.5);
  EXPECT_DOUBLE_EQ(greet.trigger_far, 2.1);
  ASSERT_EQ(greet.masks.size(), 1u);
  EXPECT_EQ(greet.masks[0].scopes[0].name, "right_arm");
  EXPECT_EQ(view.masks[0].scopes[3].name, "right_arm");
  EXPECT_EQ(view.masks[0].scopes[3].rotation, 1);  // the gesture keys move it
  int gestures = 0;
  for (const authoring::KeySpec& k : spec.keys) gestures += k.gesture != authoring::Gesture::kNone;
  EXPECT_EQ(gestures, 1);  // 6 keys, 60 degrees apart: only the front one is within 50 degrees
}

// The character's lines (docs/speech.md) are written as `lines:`, each markup as it was given.
TEST(SceneWriter, LinesAreWrittenWithTheirMarkup) {
  ScenePlacement c = Placed();
  c.behaviour.idle_clips = {"Survey"};
  c.behaviour.lines = {{"start", "<gesture name=\"Wave\"/>Hello! It's me."}, {"lost", "Where did you go?"}};
  const authoring::Scene s = authoring::ParseScene(SceneYaml(c), "/tmp/placed.yaml");
  const std::vector<authoring::LineSpec>& lines = s.characters[0].lines;
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].when, authoring::LineCue::kStart);
  EXPECT_EQ(lines[0].say, "<gesture name=\"Wave\"/>Hello! It's me.");
  EXPECT_EQ(lines[1].when, authoring::LineCue::kLost);
  EXPECT_EQ(lines[1].say, "Where did you go?");
}

TEST(SceneWriter, NoBehaviourKeepsTheDefaultSchedule) {
  const authoring::Scene s = authoring::ParseScene(SceneYaml(Placed()), "/tmp/placed.yaml");
  EXPECT_FALSE(s.characters[0].idle.given);
  EXPECT_FALSE(s.characters[0].schedule.given);
}

}  // namespace
}  // namespace arview::app
