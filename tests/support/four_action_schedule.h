#pragma once
// The four-action schedule of issue 13's speed goal, on the 54-joint BCN_Epileptic (Debian
// package assimp-testmodels), shared by bench_anim (its cost) and anim_authoring's tests (that
// an update allocates nothing):
//   idle     the idle synthesizer learned from the character's clip Epileptisch, layer 0
//   view     the view-adaptive blend of 8 generated look-at keys every 45°, layer 1
//   gesture  a gesture fading in and out (cosine over 30% of its length at each end), masked
//            to the torso, layer 2: either the mirrored clip or a generated point gesture
//            (the right arm pointing by two-bone IK along a viewpoint 30° to the left, the
//            look-at chain turned toward it, over Epileptisch)
//   arm      Epileptisch looped at weight 0.5, masked to the left arm, layer 2
//
//   FourActionSchedule s(FourActionSchedule::Gesture::kPoint, /*dib=*/false);
//   for (...) { const anim::AnimatorFrame& f = s.Step(1.0 / 60); ... }

#include "anim_authoring/animator_builder.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/scene.h"

#include <memory>
#include <string>

namespace arview::testing {

inline const char* kBcnEpileptic = "/usr/share/assimp/models/X/BCN_Epileptic.X";

class FourActionSchedule {
 public:
  enum class Gesture { kMirroredClip, kPoint };

  FourActionSchedule(Gesture gesture, bool dib)
      : character_(authoring::ParseScene(SceneText(gesture, dib), "four_action.yaml").characters[0]),
        animator_(authoring::BuildAnimator(character_)) {
    const anim::Clip* base = character_.character().FindClip("Epileptisch");
    gesture_length_ = base->duration;
    if (gesture == Gesture::kPoint) AddPointGesture(*base);
    gesture_ = animator_->schedule().FindByName("gesture");
  }

  // One frame `dt` later: re-times the gesture when it has ended (so it keeps fading in and
  // out), moves the viewer round the character at 100°/s, 5° up, and updates the animator.
  const anim::AnimatorFrame& Step(double dt) {
    t_ += dt;
    anim::Schedule& schedule = animator_->schedule();
    if (t_ > schedule.Find(gesture_)->start + gesture_length_) schedule.Retime(gesture_, t_);
    inputs_.viewpoint = anim::DirectionFromAzimuthElevation(100 * t_, 5);
    return animator_->Update(t_, inputs_);
  }

  anim::Animator& animator() { return *animator_; }
  const authoring::AnimatedCharacter& character() const { return character_; }
  double time() const { return t_; }

 private:
  static std::string SceneText(Gesture gesture, bool dib) {
    std::string text = std::string("characters:\n  - asset: ") + kBcnEpileptic + "\n    blend: {method: " +
                       (dib ? "dib" : "dlb") + "}\n    idle: {clips: [Epileptisch], seed: 1}\n    keys:\n";
    for (int k = 0; k < 8; ++k) text += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
    text += R"(    schedule:
      actions:
        - name: idle
          object: {idle: true}
          keep_rendering: true
        - name: view
          object: {view_adaptive: true}
          keep_rendering: true
          layer: 1
        - name: arm
          object: {clip: Epileptisch, loop: true}
          layer: 2
          weight: 0.5
          mask: {default: 0, left_arm: 1}
)";
    if (gesture == Gesture::kMirroredClip)
      text += R"(        - name: gesture
          object: {clip: Epileptisch, mirror: true}
          layer: 2
          curve: {shape: cosine-fade, in: 0.3, out: 0.3}
          mask: {default: 0, torso: 1}
)";
    return text;
  }

  void AddPointGesture(const anim::Clip& base) {
    const anim::Skeleton& sk = character_.character().skeleton;
    const authoring::CharacterSpec& spec = character_.spec();
    const anim::ArmChain arm = authoring::MakeArmChain(sk, {}, authoring::ArmSide::kRight, {}, spec.forward, spec.up);
    auto clip = std::make_shared<const anim::Clip>(authoring::GenerateGestureClip(
        sk, &base, &character_.lookat_chain(), arm, authoring::Gesture::kPoint, anim::DirectionFromAzimuthElevation(30, 0)));
    anim::Action point;
    point.object = std::make_shared<anim::ClipSource>(character_.shared_skeleton(), clip);
    point.name = "gesture";
    point.layer = 2;
    point.params.curves = {anim::Curve::CosineFade(0.3, 0.3)};
    anim::JointMask torso = anim::JointMask::Uniform(sk.size(), 0.0);
    torso.Set(anim::ResolveScope(sk, "torso"), 1.0);
    point.params.masks = {torso};
    gesture_length_ = clip->duration;
    animator_->schedule().Add(std::move(point));
  }

  authoring::AnimatedCharacter character_;
  std::unique_ptr<anim::Animator> animator_;
  int gesture_ = -1;
  double gesture_length_ = 0;
  double t_ = 0;
  anim::FrameInputs inputs_;
};

}  // namespace arview::testing
