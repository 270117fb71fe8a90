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
// itself is unchanged (184 against 177 MB on phone-fox), it is only no longer returned
// between frames.
//
// Called once at the start of the programs that process frames (app/main.cpp, the frame
// benchmarks). Under AddressSanitizer, whose allocator ignores mallopt, it does nothing.

#include <cstddef>

namespace arview {

struct HeapReuseSettings {
  // Blocks up to this size come from the heap; larger ones are still mapped and unmapped on
  // their own. 32 MiB is the ceiling glibc's own dynamic threshold rises to on 64-bit.
  std::size_t mmap_threshold_bytes = std::size_t{32} << 20;
  // The heap's free top is returned to the kernel only beyond this size.
  std::size_t trim_threshold_bytes = std::size_t{256} << 20;
};

// Applies the settings to glibc's malloc (every arena, every thread). Returns false where the
// allocator does not take them (a sanitizer's allocator, a value glibc refuses); the process
// then runs with the allocator's defaults, only slower.
bool KeepFreedHeapForReuse(const HeapReuseSettings& settings = {});

}  // namespace arview
