#pragma once
// Asset import through Assimp (authoring: runs once, at load).

#include "anim/character.h"

#include <filesystem>
#include <string>

namespace arview::authoring {

// Loads a character. Throws Error (naming the file) when the file is missing or unreadable,
// Assimp cannot parse it, or it has no skeleton (no bones and no animated nodes).
// A built-in asset ("builtin:<name>", see below) comes from the registered provider instead.
anim::Character LoadCharacter(const std::filesystem::path& path);

// Built-in characters: assets generated in code, named "builtin:<name>" wherever an asset path
// is accepted (scene files, `arview place --character`, `arview anim info`). anim_authoring/
// only routes the name; the program registers the provider (arview registers figure/'s
// humanoid, "builtin:figure"). The provider throws Error for a name it does not know.
inline constexpr const char* kBuiltinAssetPrefix = "builtin:";
bool IsBuiltinAsset(const std::filesystem::path& asset);
using BuiltinCharacterProvider = anim::Character (*)(const std::string& name);
void SetBuiltinCharacterProvider(BuiltinCharacterProvider provider);

}  // namespace arview::authoring
