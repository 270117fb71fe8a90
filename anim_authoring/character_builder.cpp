#include "anim_authoring/character_builder.h"

#include <algorithm>
#include <utility>

#include "anim/pose.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/import.h"
#include "anim_authoring/lookat.h"

namespace arview::authoring {
namespace {

struct BuiltKeys {
  std::vector<anim::ViewAdaptiveKey> keys;
  anim::LookAtChain lookat;
  anim::ArmChain arm;
};

// The key clips of `spec` on `character`: from the asset, generated (look-at, gesture), or static,
// with the chains the generated ones turn.
BuiltKeys BuildKeys(const std::shared_ptr<const anim::Character>& character, const CharacterSpec& spec) {
  BuiltKeys built;
  const anim::Character& c = *character;
  const anim::Skeleton& sk = c.skeleton;
  const std::string where = spec.where.empty() ? spec.asset.string() : spec.where;
  auto key_where = [&](const KeySpec& k) {
    return k.line > 0 && !spec.where.empty() ? spec.where.substr(0, spec.where.rfind(':')) + ":" + std::to_string(k.line)
                                              : where;
  };
  auto find_clip = [&](const KeySpec& k, const std::string& name) -> const anim::Clip& {
    const anim::Clip* clip = c.FindClip(name);
    if (!clip)
      throw anim::Error(key_where(k) + ": clip '" + name + "' does not exist in " + c.source + " (clips: " + ClipList(c) + ")");
    return *clip;
  };
  const bool any_lookat = std::any_of(spec.keys.begin(), spec.keys.end(),
                                      [](const KeySpec& k) { return k.source == KeySpec::Source::kLookAt; });
  const anim::Clip* lookat_base = nullptr;
  if (any_lookat) {
    try {
      built.lookat = MakeLookAtChain(sk, spec.lookat.chain, spec.lookat.limits_deg, spec.forward, spec.up);
    } catch (const anim::Error& e) {
      throw anim::Error(where + ": " + e.what());
    }
    if (spec.lookat.base_clip == "rest" && !c.FindClip("rest")) {
      lookat_base = nullptr;  // a static look from the rest pose
    } else if (!spec.lookat.base_clip.empty()) {
      lookat_base = c.FindClip(spec.lookat.base_clip);
      if (!lookat_base)
        throw anim::Error(where + ": lookat.base_clip '" + spec.lookat.base_clip + "' does not exist in " + c.source +
                    " (clips: " + ClipList(c) + ")");
    } else if (!c.clips.empty()) {
      lookat_base = &c.clips.front();
    }
  }
  const bool any_gesture = std::any_of(spec.keys.begin(), spec.keys.end(),
                                       [](const KeySpec& k) { return k.gesture != Gesture::kNone; });
  if (any_gesture) {
    try {
      built.arm = MakeArmChain(sk, spec.gesture.chain, spec.gesture.side, spec.gesture.limits, spec.forward, spec.up);
    } catch (const anim::Error& e) {
      throw anim::Error(where + ": " + e.what());
    }
  }
  std::vector<std::shared_ptr<const anim::Clip>> key_clips;
  for (const KeySpec& k : spec.keys) {
    switch (k.source) {
      case KeySpec::Source::kClip:
        // Alias into the character: no copy.
        key_clips.push_back(std::shared_ptr<const anim::Clip>(character, &find_clip(k, k.clip)));
        break;
      case KeySpec::Source::kLookAt:
        if (k.gesture != Gesture::kNone)
          key_clips.push_back(
              std::make_shared<const anim::Clip>(GenerateGestureClip(sk, lookat_base, &built.lookat, built.arm, k.gesture, k.viewpoint)));
        else
          key_clips.push_back(std::make_shared<const anim::Clip>(GenerateLookAtClip(sk, lookat_base, built.lookat, k.viewpoint)));
        break;
      case KeySpec::Source::kRestPose: {
        anim::Clip rest;
        rest.name = "rest";
        rest.tracks.resize(sk.size());
        key_clips.push_back(std::make_shared<const anim::Clip>(std::move(rest)));
        break;
      }
      case KeySpec::Source::kStaticPose: {
        const anim::Clip& from = find_clip(k, k.clip);
        anim::LocalPose pose(sk.size());
        anim::MustRun(anim::SamplingJob{&sk, &from, k.pose_time, false, &pose}, "static pose key");
        anim::Clip still;
        still.name = k.clip + "@" + std::to_string(k.pose_time);
        still.tracks.resize(sk.size());
        for (int j = 0; j < sk.size(); ++j) {
          still.tracks[j].rotation.push_back({0.0, pose.rigid[j].Rotation()});
          still.tracks[j].translation.push_back({0.0, pose.rigid[j].Translation()});
          still.tracks[j].scale.push_back({0.0, pose.scale[j]});
        }
        key_clips.push_back(std::make_shared<const anim::Clip>(std::move(still)));
        break;
      }
    }
  }
  for (std::size_t k = 0; k < spec.keys.size(); ++k) built.keys.push_back({spec.keys[k].viewpoint, key_clips[k]});
  return built;
}

anim::PlacedCharacterParts BuildParts(std::shared_ptr<const anim::Character> character, const CharacterSpec& spec) {
  const std::string where = spec.where.empty() ? spec.asset.string() : spec.where;
  anim::ViewAdaptiveOptions options;
  options.weights = spec.weights;
  options.blend = spec.blend;
  options.dib = spec.dib;
  options.phase = spec.phase;
  options.nlerp_sampling = spec.nlerp_sampling;
  BuiltKeys built = BuildKeys(character, spec);
  anim::PlacedCharacterParts parts;
  try {
    parts.blend = std::make_shared<anim::ViewAdaptiveBlend>(std::shared_ptr<const anim::Skeleton>(character, &character->skeleton),
                                                      std::move(built.keys), options);
  } catch (const anim::Error& e) {
    throw anim::Error(where + ": " + e.what());
  }
  parts.character = std::move(character);
  parts.placement = spec.placement();
  parts.name = spec.name;
  parts.where = spec.where;
  for (const KeySpec& key : spec.keys) {
    parts.key_viewpoints.push_back(key.viewpoint);
    parts.key_labels.push_back(KeySourceLabel(key));
  }
  parts.lookat = std::move(built.lookat);
  parts.arm = built.arm;
  if (spec.gaze.enabled) {
    anim::GazeSetup gaze{anim::FindGazeRig(parts.character->skeleton, spec.forward, spec.up), spec.gaze.options};
    if (gaze.rig.valid()) parts.gaze = gaze;  // a character without eyes: nothing (gaze.h)
  }
  return parts;
}

}  // namespace

std::string ClipList(const anim::Character& c) {
  std::string s;
  for (const anim::Clip& clip : c.clips) s += (s.empty() ? "" : ", ") + clip.name;
  return s.empty() ? "none" : s;
}


AnimatedCharacter::AnimatedCharacter(const CharacterSpec& spec)
    : AnimatedCharacter(std::make_shared<const anim::Character>(LoadCharacter(spec.asset)), spec) {}

AnimatedCharacter::AnimatedCharacter(std::shared_ptr<const anim::Character> character, const CharacterSpec& spec)
    : anim::PlacedCharacter(BuildParts(std::move(character), spec)), spec_(spec) {}

}  // namespace arview::authoring
