#include "base/heap_reuse.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>

#include "base/sanitizer_build.h"

namespace arview {
namespace {

// A block of the size of SIFT's scale-space images and of a full-HD frame comes from the heap
// and, freed, stays in it for the next frame. With glibc's defaults (in a fresh process) it is
// a mapping of its own, unmapped on free.
// Under a sanitizer, whose allocator maps such a block on its own whatever mallopt was told, the
// settings are reported as not taken.
TEST(KeepFreedHeapForReuse, AFreedFrameSizedBlockStaysInTheHeap) {
  if (kSanitizedAllocator) {
    EXPECT_FALSE(KeepFreedHeapForReuse()) << "the sanitizer's allocator takes no mallopt settings";
    return;
  }
  ASSERT_TRUE(KeepFreedHeapForReuse());
  constexpr std::size_t kBlockBytes = std::size_t{6} << 20;
  const struct mallinfo2 before = mallinfo2();
  auto* block = static_cast<unsigned char*>(std::malloc(kBlockBytes));
  ASSERT_NE(block, nullptr);
  std::memset(block, 0x5a, kBlockBytes);
  const struct mallinfo2 held = mallinfo2();
  EXPECT_EQ(held.hblkhd, before.hblkhd) << "the block was mapped on its own";
  EXPECT_EQ(block[kBlockBytes / 2], 0x5a);
  std::free(block);
  const struct mallinfo2 after = mallinfo2();
  EXPECT_GE(after.fordblks, kBlockBytes) << "the freed block was returned to the kernel";
}

// mallopt takes an int: a larger value must be reported, not wrapped into a small or negative one.
TEST(KeepFreedHeapForReuse, ValuesBeyondMalloptsRangeAreReported) {
  HeapReuseSettings beyond_int;
  beyond_int.trim_threshold_bytes = std::size_t{1} << 40;
  EXPECT_FALSE(KeepFreedHeapForReuse(beyond_int));
}

}  // namespace
}  // namespace arview
