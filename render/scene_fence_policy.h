#pragma once
// What read-backs do with llvmpipe's scene fences (render::SceneFences, render/gl_objects.h),
// process-wide: the hold that fixed issue 57's live crash unless a benchmark sets another, to
// time the hold against what it replaced (bench_render's BM_ArFrameFences, docs/render.md "The
// fence hold's cost"). The other two bring the crash back: for timing only.

namespace arview::render {

enum class SceneFencePolicy {
  kHold,           // the fix: the newest scene's fence held until a later one has signalled
  kReleaseAtOnce,  // a sync object made and deleted at once: the scene handed over, no fence held
  kNone            // no sync object: the read-backs as before the fix
};

void SetSceneFencePolicyForTiming(SceneFencePolicy policy);

}  // namespace arview::render
