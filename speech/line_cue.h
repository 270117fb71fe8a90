#pragma once
// When a scene character says a line (docs/speech.md, "Lines in scenes"): the scene file names it
// (anim_authoring's `lines:`), the frame path watches for it (app/pipeline/character_speech.h).

#include "base/enum_table.h"

namespace arview::speech {

enum class LineCue {
  kStart,   // the first frame the viewer is tracked
  kNear,    // the viewer comes within `near` (re-armed beyond `far`)
  kBehind,  // the viewer walks behind the character
  kLost,    // tracking lost for a while
  kFound,   // tracking back after such a loss
};
constexpr auto EnumNames(LineCue) {
  return EnumTable<LineCue, 5>{{{LineCue::kStart, "start"},
                                {LineCue::kNear, "near"},
                                {LineCue::kBehind, "behind"},
                                {LineCue::kLost, "lost"},
                                {LineCue::kFound, "found"}}};
}

}  // namespace arview::speech
