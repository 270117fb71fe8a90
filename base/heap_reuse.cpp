#include "base/heap_reuse.h"

#include <malloc.h>

#include <limits>

#include "base/sanitizer_build.h"

namespace arview {

bool KeepFreedHeapForReuse(const HeapReuseSettings& settings) {
  constexpr auto kMaxOption = static_cast<std::size_t>(std::numeric_limits<int>::max());
  if (settings.mmap_threshold_bytes > kMaxOption || settings.trim_threshold_bytes > kMaxOption) return false;
  // The sanitizers' allocators take no mallopt settings: ASan's mallopt says so (0), TSan's
  // process still has glibc's, which says yes (1) to settings no allocation then follows.
  if (kSanitizedAllocator) return false;
  // Setting either disables glibc's dynamic thresholds, so both are set: the trim threshold
  // alone would leave every block above 128 KiB mapped afresh (phone-fox: 140 -> 210 ms).
  const bool mmap_set = mallopt(M_MMAP_THRESHOLD, static_cast<int>(settings.mmap_threshold_bytes)) == 1;
  const bool trim_set = mallopt(M_TRIM_THRESHOLD, static_cast<int>(settings.trim_threshold_bytes)) == 1;
  return mmap_set && trim_set;
}

}  // namespace arview
