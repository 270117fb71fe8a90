#pragma once
// A disk cache for the characters' PRT transfer (render/prt.h). Ray casting the transfer takes
// ~2 s for a 25k-triangle character on two cores, at every start of `render`, `replay`, `run`,
// `view` and `demo`; the transfer depends only on the bind-pose meshes and the ray-casting
// options, so it is computed once and read back afterwards (issue 14: "the precomputation's
// time reported ..., cached").
//
// Key: a 64-bit FNV-1a hash over a format version, the options that change the result
// (directions, min_hit_fraction, skip_adjacent; not the thread count) and every mesh's positions,
// normals and indices, bit for bit. File: <folder>/<key as 16 hex digits>.prt, written atomically:
//   "ARVPRT1\n", key (u64), mesh count (u32), per mesh its vertex count (u32),
//   9 floats per vertex, rays (i64), occluded share (f64), FNV-1a of everything before (u64).
// A file that is not exactly that (truncated, another key, other vertex counts, a non-finite
// value, a wrong checksum) is not used: the transfer is computed again and the file replaced.
// The cache is an optimisation only: a folder that cannot be written costs the time, not the run.

#include <cstdint>
#include <filesystem>
#include <string>

#include "render/prt.h"

namespace arview::render {

// $ARVIEW_CACHE_DIR/prt, else $XDG_CACHE_HOME/arview/prt, else $HOME/.cache/arview/prt;
// empty when none of them is set.
std::filesystem::path DefaultPrtCacheFolder();

std::uint64_t PrtCacheKey(const anim::Character& character, const PrtOptions& options);

struct PrtCacheResult {
  CharacterTransfer transfer;
  bool from_cache = false;
  std::filesystem::path file;  // the cache file read or written (empty: no cache folder)
  std::string note;            // why a cache file present was not used, or could not be written
};

// The transfer from `folder`'s cache when a valid file is there, else computed (and stored).
// An empty `folder` computes without caching.
PrtCacheResult ShadowedTransferCached(const anim::Character& character, const PrtOptions& options,
                                      const std::filesystem::path& folder);

}  // namespace arview::render
