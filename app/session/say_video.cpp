#include "app/session/say_video.h"

#include <cmath>
#include <memory>

#include <nlohmann/json.hpp>

#include "anim_authoring/scene.h"
#include "app/session/character_setup.h"
#include "app/session/scene_lines.h"
#include "base/atomic_file.h"
#include "calib/camera.h"
#include "render/ar_renderer.h"
#include "video/sinks.h"

namespace arview::app {

namespace {

const authoring::CharacterSpec& ChooseCharacter(const authoring::Scene& scene, const SayOptions& o) {
  if (scene.characters.empty()) throw anim::Error(o.scene.string() + ": the scene has no characters");
  if (o.character.empty()) return scene.characters.front();
  std::string names;
  for (const authoring::CharacterSpec& c : scene.characters) {
    if (c.name == o.character) return c;
    names += (names.empty() ? "" : ", ") + c.name;
  }
  throw anim::Error(o.scene.string() + ": no character '" + o.character + "' (characters: " + names + ")");
}

// Where the head is in the map (the joint named Head, else the highest joint at rest).
Eigen::Vector3d HeadInMap(const authoring::AnimatedCharacter& ch) {
  const anim::Skeleton& sk = ch.character().skeleton;
  std::vector<Eigen::Matrix4d> model(sk.size());
  int head = sk.Find("Head");
  const Eigen::Vector3d up = ch.spec().up;
  for (int j = 0; j < sk.size(); ++j) {
    const Eigen::Matrix4d local = sk.rest[j].ToMatrix();
    model[j] = sk.parents[j] < 0 ? Eigen::Matrix4d(sk.root_parent * local) : Eigen::Matrix4d(model[sk.parents[j]] * local);
    if (sk.Find("Head") < 0 && (head < 0 || model[j].block<3, 1>(0, 3).dot(up) > model[head].block<3, 1>(0, 3).dot(up))) head = j;
  }
  const Eigen::Vector3d at = head >= 0 ? Eigen::Vector3d(model[head].block<3, 1>(0, 3)) : Eigen::Vector3d::Zero();
  return (ch.spec().placement().ModelToMap() * at.homogeneous()).head<3>();
}

// A camera `distance` in front of the head, level, looking at it (world → camera).
calib::Pose CloseUp(const authoring::AnimatedCharacter& ch, double distance) {
  const anim::Placement p = ch.spec().placement();
  const Eigen::Vector3d up = p.UpInMap();
  Eigen::Vector3d front = p.Rotation() * p.forward;
  front = (front - front.dot(up) * up).normalized();
  const Eigen::Vector3d head = HeadInMap(ch);
  const Eigen::Vector3d centre = head + distance * front;
  Eigen::Matrix3d camera_to_world;
  const Eigen::Vector3d z = -front, y = -up;
  camera_to_world.col(0) = y.cross(z);
  camera_to_world.col(1) = y;
  camera_to_world.col(2) = z;
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(camera_to_world), centre);
}

nlohmann::ordered_json FrameCurves(double t, const anim::AnimatorFrame& f, const anim::Skeleton& sk) {
  nlohmann::ordered_json visemes = nlohmann::ordered_json::object();
  for (const char* name : anim::VisemeTargetNames()) {
    const int target = sk.FindMorphTarget(name);
    visemes[name] = target >= 0 && target < static_cast<int>(f.morph_weights.size()) ? f.morph_weights[target] : 0.0f;
  }
  return {{"time", t}, {"talking", f.face.talking}, {"mouth_open", f.face.jaw_open}, {"lip_seal", f.face.lip_seal},
          {"visemes", visemes}};
}

std::uint64_t Fnv1a(const std::vector<std::int16_t>& samples) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::int16_t s : samples)
    for (int b = 0; b < 2; ++b) {
      h ^= static_cast<std::uint8_t>(static_cast<std::uint16_t>(s) >> (8 * b));
      h *= 1099511628211ull;
    }
  return h;
}

}  // namespace

SayResult RenderSpokenLine(const SayOptions& o) {
  const authoring::Scene scene = authoring::LoadScene(o.scene);
  authoring::CharacterSpec spec = ChooseCharacter(scene, o);
  const std::string origin = o.scene.string() + ", the line to say";
  // The scene's own lines are not said here, only the one given; the schedule gets room for its
  // actions (MakeLayeredAnimator counts the spec's lines' tags), its errors named as this line's.
  speech::ParseMarkup(o.text, origin);
  authoring::LineSpec said;
  said.say = o.text;
  spec.lines = {said};
  authoring::AnimatedCharacter character(spec);
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(character);
  std::vector<ReadyLine> lines =
      PrepareLines(character, {{origin, o.text, SpeechCue::kStart}}, o.voice.empty() ? spec.voice : o.voice,
                   o.voice.empty() ? spec.where : std::string("--voice"));
  SpeechOptions speech_options;
  speech_options.forward = spec.forward;
  speech_options.up = spec.up;
  speech_options.character = spec.name;
  animator->SetSpeech(std::make_unique<CharacterSpeech>(std::move(lines), speech_options));

  const double f = 0.9 * o.size.width;  // about 58° across: a face and shoulders at 0.6 m
  const calib::Camera camera = calib::Camera::Pinhole(o.size.width, o.size.height, f, f, (o.size.width - 1) / 2.0, (o.size.height - 1) / 2.0);
  const calib::Pose pose = CloseUp(character, o.distance);
  std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create(o.gl);
  render::ArOptions ar;
  ar.lighting = render::LightingMode::kFixed;
  ar.cast_shadow = false;
  render::ArRenderer renderer(*context, camera, ar);
  renderer.AddCharacter(character.character(), spec.placement());
  const cv::Mat background(o.size, CV_8UC3, cv::Scalar(96, 96, 96));

  PendingOutput pending(o.out);
  const bool folder = !o.out.has_extension();
  // A video file gets the line's sound, from its first frame (the line starts there).
  std::unique_ptr<video::FrameSink> sink =
      video::OpenSink(folder ? pending.sink_target() : pending.partial().string(), o.size, o.fps, {},
                      folder ? std::nullopt : std::optional(video::AudioTrackOptions{}));
  nlohmann::ordered_json curves = nlohmann::ordered_json::array();
  const double duration = animator->speech()->lines().front().duration_s() + o.tail_seconds;
  SayResult result;
  result.frames = std::max(1, static_cast<int>(std::ceil(duration * o.fps)));
  for (int i = 0; i < result.frames; ++i) {
    const double t = i / o.fps;
    const anim::AnimatorFrame& frame = animator->Update(pose.Center(), t);
    const anim::AnimatorFrame* frames[] = {&frame};
    sink->Write(renderer.Render(background, pose, frames));
    if (i == 0 && sink->HasAudio()) sink->WriteAudio(0, animator->speech()->utterances().at(0).line->samples);
    if (!o.curves.empty()) curves.push_back(FrameCurves(t, frame, character.character().skeleton));
  }
  sink->Close();
  result.utterance = animator->speech()->utterances().at(0);
  if (!o.curves.empty()) {
    const std::vector<std::int16_t>& samples = result.utterance.line->samples;
    char hash[24];
    std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(Fnv1a(samples)));
    nlohmann::ordered_json j = {{"text", animator->speech()->lines().front().text},
                                {"samples", samples.size()},
                                {"sample_rate", speech::SpokenLine::kSampleRate},
                                {"samples_fnv1a64", hash},
                                {"fps", o.fps},
                                {"frames", curves}};
    WriteFileAtomically(o.curves, j.dump(1) + "\n");
  }
  pending.Commit();
  result.renderer = context->Description();
  return result;
}

}  // namespace arview::app
