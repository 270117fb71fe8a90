#pragma once
// Freed heap memory kept in the process for the next frame, instead of being handed back to
// the kernel and faulted in again.
//
// Why: OpenCV's SIFT allocates its scale space afresh on every call (the doubled image and
// two pyramids of float images, tens of MB for a 360x640 frame) and frees it on return.
// glibc's defaults serve blocks above a threshold (128 KiB, raised dynamically to the largest
// block freed) by mmap and trim the heap's top once more than twice that is free, so an
// extraction could fault all of it in again. It did in `arview track` on phone-fox
// (1080x1920; the tracker on the main thread): ~7 000 minor page faults an extraction, and a
// guided-matching frame cost 153 ms CPU instead of 50, a relocalization 88-98 ms instead of
// 41, the frame after a guided one ~10 ms instead of ~3 (docs/tracker.md, "2026-12-04
// (night)"). With the heap kept, memory up to the process's peak stays mapped: the peak
// grows little (phone-fox: 184 against 177 MB; a replay of the 1920x1080 room: 433 against
// 408 MB, flat over repeated loops), it is only no longer returned between frames.
//
// Called once at the start of the programs that process frames (app/cli/main.cpp, the frame
// benchmarks). Under AddressSanitizer or ThreadSanitizer, whose allocators ignore mallopt, it does
// nothing and says so.

#include <cstddef>

namespace arview {

struct HeapReuseSettings {
  // Blocks up to this size come from the heap; larger ones are still mapped and unmapped on
  // their own. 8 MiB holds SIFT's largest image at 640x480 (the doubled frame, 4.9 MB) and a
  // 1920x1080 BGR frame (6.2 MB). 32 MiB was as fast but held 480 instead of 408 MB in a
  // replay of 1920x1080 frames, where the pipeline's threads each keep an arena.
  std::size_t mmap_threshold_bytes = std::size_t{8} << 20;
  // A heap's free top is returned to the kernel only beyond this size. 32 MiB already let
  // phone-fox's relocalization fault its pages in again (frame 18: 79 ms instead of 34).
  std::size_t trim_threshold_bytes = std::size_t{64} << 20;
};

// Applies the settings to glibc's malloc (every arena, every thread). Returns false where the
// allocator does not take them (a sanitizer's allocator, a value glibc refuses); the process
// then runs with the allocator's defaults, only slower.
bool KeepFreedHeapForReuse(const HeapReuseSettings& settings = {});

}  // namespace arview
