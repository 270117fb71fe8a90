#include "app/session/character_setup.h"

#include "anim_authoring/animator_builder.h"
#include "app/session/scene_lines.h"

namespace arview::app {

std::unique_ptr<LayeredAnimator> MakeLayeredAnimator(const authoring::AnimatedCharacter& character,
                                                     const std::string& idle_clip, const FadeOptions& fade) {
  const anim::Character& c = character.character();
  const authoring::CharacterSpec& spec = character.spec();
  const anim::Clip* idle = nullptr;
  if (!idle_clip.empty()) {
    idle = c.FindClip(idle_clip);
    if (!idle) throw anim::Error(c.source + ": has no clip '" + idle_clip + "' for the idle layer");
  } else if (!spec.schedule.given && !spec.idle.given && spec.lookat.base_clip != "rest") {
    if (!spec.lookat.base_clip.empty()) idle = c.FindClip(spec.lookat.base_clip);
    if (!idle && !c.clips.empty()) idle = &c.clips.front();
  }
  authoring::AnimatorOverrides overrides;
  overrides.idle_clip = idle_clip;
  overrides.hold_seconds = fade.hold_seconds;
  overrides.fade_seconds = fade.fade_seconds;
  overrides.face = SpeakingFace(character);
  overrides.played_actions = PlayedActionRoom(spec);
  std::vector<std::string> notes;
  std::unique_ptr<anim::Animator> animator = authoring::BuildAnimator(character, overrides, &notes);
  return std::make_unique<LayeredAnimator>(character, std::move(animator), idle, std::move(notes));
}

}  // namespace arview::app
