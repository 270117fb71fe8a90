#include "figure/humanoid.h"

#include "figure/rig.h"

#include "anim_authoring/import.h"

#include <string>
#include <vector>

namespace arview::figure {

anim::Character MakeHumanoid() {
  const Rig rig = BuildRig();
  anim::Character c;
  c.source = "builtin:figure";
  c.skeleton = rig.skeleton;
  AddSkin(rig, c);
  AddFaceTargets(rig, c);

  c.clips = MakeClips(rig);
  return c;
}

anim::Clip MakeHumanoidWalk() { return MakeWalkClip(BuildRig()); }

std::vector<std::string> BuiltinCharacterNames() { return {"figure"}; }

anim::Character MakeBuiltinCharacter(const std::string& name) {
  if (name == "figure") return MakeHumanoid();
  std::string known;
  for (const std::string& n : BuiltinCharacterNames()) known += (known.empty() ? "" : ", ") + std::string(authoring::kBuiltinAssetPrefix) + n;
  throw anim::Error(std::string(authoring::kBuiltinAssetPrefix) + name + ": no such built-in character (built in: " + known + ")");
}

void RegisterBuiltinCharacters() { authoring::SetBuiltinCharacterProvider(&MakeBuiltinCharacter); }

}  // namespace arview::figure
