#pragma once
// The structure of a glTF 2.0 asset (.gltf JSON or .glb binary), checked before Assimp reads it.
//
// Debian 12's Assimp (5.2.5) trusts the file: a skin without `inverseBindMatrices` (optional in
// glTF 2.0) makes its glTF 2 importer read a null pointer (issue 17's fuzz_gltf reproducer,
// assimp/assimp#3465), and an index or a byte range it does not check is a read outside its
// buffers. So what the file says is checked here first, against the glTF 2.0 specification:
// - GLB: the 12-byte header (magic, version 2, length = the file's size), every chunk inside
//   the file and 4-byte aligned, the first chunk JSON, a BIN chunk at most once;
// - the JSON parsed with nlohmann-json (UTF-8 checked, nesting at most 64 levels);
// - every index (scene, node, mesh, skin, accessor, bufferView, buffer, material, texture,
//   image, sampler) a non-negative integer inside its array; the node graph a forest (no node
//   with two parents, no cycle);
// - every byte range inside what holds it: bufferViews inside their buffer, accessors (and
//   sparse accessors) inside their bufferView, the GLB's buffer inside its BIN chunk, an
//   external buffer inside its file (resolved inside the asset's folder), a data: URI long
//   enough;
// - skins with joints and inverse bind matrices (MAT4 floats, one per joint);
// - the values of JOINTS_n below the skin's joint count and of the index accessors below the
//   vertex count, read from the buffers.
// What stays unchecked is listed in docs/reliability.md (the image files' contents, the
// floats' values, extensions).

#include <filesystem>

namespace arview::authoring {

// True when the file is one this check reads: a GLB (by its magic), or a .gltf/.glb name.
bool IsGltfAsset(const std::filesystem::path& file);

// Throws anim::Error("<file>: <what is wrong>") unless the asset's structure is sound.
void CheckGltfStructure(const std::filesystem::path& file);

}  // namespace arview::authoring
