#pragma once
// Whether this build runs under a sanitizer whose allocator replaces glibc's (ASan, TSan; MSan
// under clang). Such a build's malloc takes no mallopt settings (base/heap_reuse.cpp), counting
// allocations goes through the sanitizer's hooks (anim_authoring/no_allocation_test.cpp), and its
// tests run several times slower (tests/support/sanitizer_slowdown.h). One definition for all:
// the macro where the preprocessor must decide (whether malloc is replaced), the constant
// elsewhere.

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ARVIEW_SANITIZED_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define ARVIEW_SANITIZED_ALLOCATOR 1
#endif
#endif

namespace arview {

#ifdef ARVIEW_SANITIZED_ALLOCATOR
inline constexpr bool kSanitizedAllocator = true;
#else
inline constexpr bool kSanitizedAllocator = false;
#endif

}  // namespace arview
