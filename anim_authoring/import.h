#pragma once
// Asset import through Assimp (authoring: runs once, at load).

#include "anim/character.h"

#include <filesystem>

namespace arview::anim {

// Loads a character. Throws Error (naming the file) when the file is missing or unreadable,
// Assimp cannot parse it, or it has no skeleton (no bones and no animated nodes).
Character LoadCharacter(const std::filesystem::path& path);

}  // namespace arview::anim
