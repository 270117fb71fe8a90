#include "app/placement/scene_writer.h"

#include <Eigen/Geometry>
#include <yaml-cpp/emitter.h>
#include <yaml-cpp/emittermanip.h>

#include <algorithm>

#include "anim_authoring/scene.h"
#include "base/atomic_file.h"

namespace arview::app {

namespace {

void EmitVector(YAML::Emitter& y, const char* key, std::initializer_list<double> values) {
  y << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double v : values) y << v;
  y << YAML::EndSeq;
}

// The character's `lines:` (docs/speech.md), each `say:` quoted as the emitter sees fit.
void EmitLines(YAML::Emitter& y, const std::vector<PlacedBehaviour::Line>& lines) {
  if (lines.empty()) return;
  y << YAML::Key << "lines" << YAML::Value << YAML::BeginSeq;
  for (const PlacedBehaviour::Line& l : lines)
    y << YAML::BeginMap << YAML::Key << "when" << YAML::Value << l.when << YAML::Key << "say" << YAML::Value << YAML::SingleQuoted
      << l.say << YAML::EndMap;
  y << YAML::EndSeq;
}

void EmitBehaviour(YAML::Emitter& y, const PlacedBehaviour& b) {
  const bool idle = !b.idle_clips.empty();
  if (idle) {
    y << YAML::Key << "idle" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "clips" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const std::string& clip : b.idle_clips) y << clip;
    y << YAML::EndSeq;
    y << YAML::Key << "seed" << YAML::Value << b.idle_seed;
    y << YAML::EndMap;
  }
  y << YAML::Key << "schedule" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "tracking_loss" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "hold" << YAML::Value
    << b.loss_hold << YAML::Key << "fade" << YAML::Value << b.loss_fade << YAML::Key << "action" << YAML::Value << "view"
    << YAML::EndMap;
  y << YAML::Key << "actions" << YAML::Value << YAML::BeginSeq;
  y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << "idle";
  if (idle) {
    y << YAML::Key << "object" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "idle" << YAML::Value << true
      << YAML::EndMap;
  } else {
    y << YAML::Key << "object" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "pose" << YAML::Value << "rest"
      << YAML::EndMap;
  }
  y << YAML::Key << "keep_rendering" << YAML::Value << true << YAML::EndMap;

  y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << "view";
  y << YAML::Key << "object" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "view_adaptive" << YAML::Value
    << true << YAML::EndMap;
  y << YAML::Key << "keep_rendering" << YAML::Value << true << YAML::Key << "layer" << YAML::Value << 1;
  if (idle) {
    // The look-at turns the body (the root's rotation), the spine, neck and head; the root's
    // translation (weight shifts), the legs and the arms keep the idle's motion.
    y << YAML::Key << "mask" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "default" << YAML::Value << 0
      << YAML::Key << "root" << YAML::Value << YAML::BeginMap << YAML::Key << "rotation" << YAML::Value << 1 << YAML::Key
      << "translation" << YAML::Value << 0 << YAML::EndMap << YAML::Key << "torso" << YAML::Value << 1 << YAML::Key
      << "left_arm" << YAML::Value << 0 << YAML::Key << "right_arm" << YAML::Value << (b.front_gesture.empty() ? 0 : 1)
      << YAML::EndMap;
  }
  y << YAML::EndMap;

  if (!b.greet_clip.empty() && b.greet_within > 0) {
    y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << "greet";
    y << YAML::Key << "object" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "clip" << YAML::Value
      << b.greet_clip << YAML::EndMap;
    y << YAML::Key << "layer" << YAML::Value << 2;
    y << YAML::Key << "curve" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "shape" << YAML::Value
      << "cosine-fade" << YAML::Key << "in" << YAML::Value << 0.15 << YAML::Key << "out" << YAML::Value << 0.15
      << YAML::EndMap;
    y << YAML::Key << "mask" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "default" << YAML::Value << 0
      << YAML::Key << b.greet_scope << YAML::Value << 1 << YAML::EndMap;
    y << YAML::Key << "trigger" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "near" << YAML::Value
      << b.greet_within << YAML::Key << "far" << YAML::Value << 1.4 * b.greet_within << YAML::EndMap;
    y << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::EndMap;
  EmitLines(y, b.lines);
}

}  // namespace

std::string SceneYaml(const ScenePlacement& c) {
  const Eigen::Quaterniond q(c.anchor.rotation);
  YAML::Emitter y;
  y.SetDoublePrecision(9);  // %.9g as before: metres to the nanometre, quaternions to 1e-9
  y.SetIndent(2);
  y.SetSeqFormat(YAML::Block);
  std::string comment = c.comment;  // one line: a newline would end the comment
  for (char& ch : comment)
    if (ch == '\n' || ch == '\r') ch = ' ';
  if (!comment.empty()) y << YAML::Comment(comment) << YAML::Newline;
  y << YAML::Comment("Written by 'arview place'; edit freely (format: docs/anim.md).") << YAML::Newline;
  y << YAML::BeginMap;
  y << YAML::Key << "characters" << YAML::Value << YAML::BeginSeq << YAML::BeginMap;
  y << YAML::Key << "name" << YAML::Value << c.name;
  // Double-quoted so that a path holding " #" or ": " reads back as written.
  y << YAML::Key << "asset" << YAML::Value << YAML::DoubleQuoted << c.asset.string();
  y << YAML::Key << "scale" << YAML::Value << 1;
  y << YAML::Key << "anchor" << YAML::Value << YAML::BeginMap;
  EmitVector(y, "position", {c.anchor.position.x(), c.anchor.position.y(), c.anchor.position.z()});
  EmitVector(y, "rotation", {q.x(), q.y(), q.z(), q.w()});
  y << YAML::Key << "scale" << YAML::Value << c.anchor.scale;
  y << YAML::EndMap;
  y << YAML::Key << "weights" << YAML::Value << YAML::Flow << YAML::BeginMap;
  y << YAML::Key << "mode" << YAML::Value << "inverse-distance" << YAML::Key << "distance" << YAML::Value << "geodesic"
    << YAML::Key << "alpha" << YAML::Value << 3;
  y << YAML::EndMap;
  y << YAML::Key << "blend" << YAML::Value << YAML::Flow << YAML::BeginMap;
  y << YAML::Key << "method" << YAML::Value << "dlb" << YAML::Key << "precision" << YAML::Value << 0.001
    << YAML::Key << "max_iterations" << YAML::Value << 32;
  y << YAML::EndMap;
  if (!c.base_clip.empty()) {
    y << YAML::Key << "lookat" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "base_clip" << YAML::Value << c.base_clip;
    y << YAML::EndMap;
  }
  y << YAML::Key << "keys" << YAML::Value << YAML::BeginSeq;
  for (int k = 0; k < c.key_count; ++k) {
    const double azimuth = 360.0 * k / c.key_count;
    const double off_front = std::min(azimuth, 360.0 - azimuth);
    y << YAML::BeginMap;
    y << YAML::Key << "azimuth" << YAML::Value << azimuth;
    y << YAML::Key << "elevation" << YAML::Value << c.key_elevation_deg;
    if (!c.behaviour.front_gesture.empty() && off_front <= c.behaviour.gesture_within_deg + 1e-9) {
      y << YAML::Key << "gesture" << YAML::Value << c.behaviour.front_gesture;
    } else {
      y << YAML::Key << "generate" << YAML::Value << "lookat";
    }
    y << YAML::EndMap;
  }
  y << YAML::EndSeq;
  if (!c.behaviour.empty()) EmitBehaviour(y, c.behaviour);
  y << YAML::EndMap << YAML::EndSeq << YAML::EndMap;
  if (!y.good()) throw anim::Error("scene writer: " + y.GetLastError());
  return std::string(y.c_str()) + "\n";
}

void WriteSceneFile(const ScenePlacement& c, const std::filesystem::path& file) {
  const std::string text = SceneYaml(c);
  authoring::ParseScene(text, file);  // throws anim::Error when the text would not load
  WriteFileAtomically(file, text);
}

}  // namespace arview::app
