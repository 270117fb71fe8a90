#include "app/session/scene_lines.h"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <thread>

#include "anim/blendable.h"
#include "figure/face_targets.h"
#include "speech/speech_queue.h"

namespace arview::app {

namespace {

std::string Where(const std::string& origin, const speech::MarkupTag& tag) {
  return origin + ": <" + std::string(ToString(tag.kind)) + "> at character " + std::to_string(tag.position) + ": ";
}

std::optional<figure::Expression> ExpressionNamed(const std::string& name) {
  for (figure::Expression e : figure::kExpressions)
    if (name == figure::ExpressionName(e)) return e;
  return std::nullopt;
}

std::string ExpressionList() {
  std::string list;
  for (figure::Expression e : figure::kExpressions) list += (list.empty() ? "" : ", ") + std::string(figure::ExpressionName(e));
  return list;
}

// The upper-body joints a gesture clip moves: those of the torso scope whose rotation turns more
// than `min_deg` from its first key at some key. The rest of the upper body stays with the layers
// below: with the whole torso masked in, a wave turned the head back to the body's front while
// the look-at had it on the viewer (the demo's head was up to 43 deg off the camera while it said
// hello, against 21 deg without the line); a nod still moves the neck and head.
std::vector<int> UpperBodyJointsMoved(const anim::Skeleton& skeleton, const anim::Clip& clip, double min_deg) {
  std::vector<int> moved;
  const double min_rad = min_deg * std::numbers::pi / 180.0;
  for (int joint : anim::ResolveScope(skeleton, "torso")) {
    const auto& keys = clip.tracks.at(static_cast<std::size_t>(joint)).rotation;
    const bool turns = std::any_of(keys.begin(), keys.end(), [&](const auto& key) {
      return key.value.angularDistance(keys.front().value) > min_rad;
    });
    if (turns) moved.push_back(joint);
  }
  return moved;
}

// <gesture name="Wave"/>: the character's clip of that name (GestureClipAction).
anim::Action GestureAction(const authoring::AnimatedCharacter& ch, const speech::TimedTag& t, const std::string& origin,
                           const LineActionTiming& timing) {
  std::optional<anim::Action> a = GestureClipAction(ch, t.tag.target, t.time_s, timing);
  if (!a)
    throw anim::Error(Where(origin, t.tag) + "the character '" + ch.spec().name + "' has no gesture '" + t.tag.target +
                      "' (its clips: " + authoring::ClipList(ch.character()) + ")");
  return std::move(*a);
}

// <face expr="happy" intensity="0.6"/>: the expression's target weights held from its word to a
// while after the line, faded in and out; it keys weights only (every joint masked out).
anim::Action FaceAction(const authoring::AnimatedCharacter& ch, const speech::TimedTag& t, double line_end,
                        const std::string& origin, const LineActionTiming& timing) {
  const std::optional<figure::Expression> expression = ExpressionNamed(t.tag.target);
  if (!expression)
    throw anim::Error(Where(origin, t.tag) + "the expression '" + t.tag.target + "' is not one of " + ExpressionList());
  const anim::Skeleton& sk = ch.character().skeleton;
  const double length = std::max(line_end - t.time_s, 0.0) + timing.face_hold_after_line;
  auto clip = std::make_shared<anim::Clip>();
  clip->name = "say:face:" + t.tag.target;
  clip->duration = length;
  clip->tracks.resize(sk.size());
  for (const figure::TargetWeight& w : figure::ExpressionWeights(*expression, t.tag.intensity)) {
    const int target = sk.FindMorphTarget(w.target);
    if (target < 0)
      throw anim::Error(Where(origin, t.tag) + "the character '" + ch.spec().name + "' cannot show '" + t.tag.target +
                        "': it has no morph target '" + w.target + "'");
    clip->weight_tracks.push_back({target, {{0.0, w.weight}, {length, w.weight}}});
  }
  anim::Action a;
  a.object = std::make_shared<anim::ClipSource>(ch.shared_skeleton(), clip);
  a.start = t.time_s;
  a.name = clip->name;
  a.layer = timing.face_layer;
  anim::Curve fade = anim::Curve::CosineFade(std::min(timing.face_fade_in, length / 2), std::min(timing.face_fade_out, length / 2));
  fade.in_seconds = true;
  a.params.curves = {fade};
  a.params.masks = {anim::JointMask::Uniform(sk.size(), 0.0)};
  return a;
}

// Every line synthesized on the queue's thread; the caller waits for all (at load).
std::vector<speech::SpokenLine> SynthesizeAll(const std::vector<speech::MarkedLine>& marked, const std::vector<LineRequest>& requests,
                                              speech::Voice voice) {
  std::vector<speech::SpokenLine> spoken(marked.size());
  if (marked.empty()) return spoken;
  speech::SpeechQueue queue(voice, marked.size());
  for (std::size_t i = 0; i < marked.size(); ++i) queue.Submit(i, marked[i].text);
  for (std::size_t done = 0; done < marked.size();) {
    std::optional<speech::SpeechResult> r = queue.TakeFinished();
    if (!r) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    if (!r->error.empty()) throw speech::SpeechError(requests[r->id].origin + ": " + r->error);
    spoken[r->id] = std::move(r->line);
    ++done;
  }
  return spoken;
}

}  // namespace

std::optional<anim::Action> GestureClipAction(const authoring::AnimatedCharacter& ch, const std::string& name, double start,
                                             const LineActionTiming& timing) {
  const anim::Character& c = ch.character();
  const anim::Clip* clip = c.FindClip(name);
  if (!clip) return std::nullopt;
  anim::Action a;
  a.object = std::make_shared<anim::ClipSource>(ch.shared_skeleton(), std::shared_ptr<const anim::Clip>(ch.shared_character(), clip));
  a.start = start;
  a.name = "say:gesture:" + name;
  a.layer = timing.gesture_layer;
  anim::Curve fade = anim::Curve::CosineFade(std::min(timing.gesture_fade_in, clip->duration / 2),
                                             std::min(timing.gesture_fade_out, clip->duration / 2));
  fade.in_seconds = true;
  a.params.curves = {fade};
  anim::JointMask mask = anim::JointMask::Uniform(c.skeleton.size(), 0.0);
  mask.Set(UpperBodyJointsMoved(c.skeleton, *clip, timing.gesture_min_turn_deg), 1.0);
  a.params.masks = {mask};
  return a;
}

ReadyLine MakeReadyLine(const authoring::AnimatedCharacter& character, const LineRequest& request,
                        const speech::MarkedLine& marked, speech::SpokenLine spoken, const LineActionTiming& timing) {
  ReadyLine line;
  line.origin = request.origin;
  line.text = marked.text;
  line.cue = request.cue;
  line.near = request.near;
  line.far = request.far;
  auto sp = std::make_shared<const speech::SpokenLine>(std::move(spoken));
  line.visemes = std::make_shared<const speech::VisemeTrack>(sp->phones);
  const double end = sp->DurationSeconds();
  for (const speech::TimedTag& t : speech::TimeTags(marked, *sp, line.origin)) {
    switch (t.tag.kind) {
      case speech::TagKind::kGesture: line.actions.push_back(GestureAction(character, t, line.origin, timing)); break;
      case speech::TagKind::kFace: line.actions.push_back(FaceAction(character, t, end, line.origin, timing)); break;
      case speech::TagKind::kGaze: line.gaze_at_viewer.push_back(t.time_s); break;
    }
  }
  line.spoken = std::move(sp);
  return line;
}

std::vector<LineRequest> SceneLineRequests(const authoring::CharacterSpec& spec) {
  const std::string file = spec.where.substr(0, spec.where.rfind(':'));
  std::vector<LineRequest> out;
  for (const authoring::LineSpec& l : spec.lines)
    out.push_back({file + ":" + std::to_string(l.line), l.say, l.when, l.near, l.far});
  return out;
}

std::vector<ReadyLine> PrepareLines(const authoring::AnimatedCharacter& character, const std::vector<LineRequest>& requests,
                                    const std::string& voice_name, const std::string& voice_origin,
                                    const LineActionTiming& timing) {
  speech::Voice voice;
  try {
    voice = speech::VoiceFromName(voice_name);
  } catch (const speech::SpeechError& e) {
    throw speech::SpeechError(voice_origin + ": " + e.what());
  }
  std::vector<speech::MarkedLine> marked;
  for (const LineRequest& r : requests) {
    marked.push_back(speech::ParseMarkup(r.markup, r.origin));
    for (const speech::MarkupTag& tag : marked.back().tags)
      if (tag.kind == speech::TagKind::kGaze && tag.target != "viewer")
        throw speech::SpeechError(Where(r.origin, tag) + "the character can look at 'viewer' only, not '" + tag.target + "'");
  }
  std::vector<speech::SpokenLine> spoken = SynthesizeAll(marked, requests, voice);
  std::vector<ReadyLine> lines;
  for (std::size_t i = 0; i < requests.size(); ++i)
    lines.push_back(MakeReadyLine(character, requests[i], marked[i], std::move(spoken[i]), timing));
  return lines;
}

std::optional<anim::FaceRig> SpeakingFace(const authoring::AnimatedCharacter& character) {
  const anim::Character& c = character.character();
  anim::FaceRig rig = anim::FindFaceRig(c.skeleton, character.spec().forward, character.spec().up);
  if (!rig.valid()) return std::nullopt;
  if (c.source == "builtin:figure") {
    const std::span<const float> shares = figure::VisemeJawShares();
    std::copy(shares.begin(), shares.end(), rig.jaw_share.begin());
    rig.jaw_open_deg = figure::kJawOpenDegrees;
  }
  return rig;
}

int PlayedActionRoom(const authoring::CharacterSpec& spec) {
  std::size_t most = 0;
  for (const LineRequest& r : SceneLineRequests(spec)) most = std::max(most, speech::ParseMarkup(r.markup, r.origin).tags.size());
  // A line's actions may still run while the next lines start (a gesture longer than its line, an
  // expression held a second after it): room for four lines' worth.
  return static_cast<int>(4 * most);
}

std::unique_ptr<CharacterSpeech> MakeCharacterSpeech(const authoring::AnimatedCharacter& character,
                                                     std::function<void(const speech::Utterance&)> on_utterance,
                                                     double start_delay_s) {
  const authoring::CharacterSpec& spec = character.spec();
  if (spec.lines.empty()) return nullptr;
  const std::string voice_origin = spec.voice_line ? spec.where.substr(0, spec.where.rfind(':')) + ":" + std::to_string(spec.voice_line)
                                                   : spec.where;
  SpeechOptions options;
  options.forward = spec.forward;
  options.up = spec.up;
  options.character = spec.name;
  options.on_utterance = std::move(on_utterance);
  options.start_delay_s = start_delay_s;
  return std::make_unique<CharacterSpeech>(PrepareLines(character, SceneLineRequests(spec), spec.voice, voice_origin),
                                           std::move(options));
}

}  // namespace arview::app
