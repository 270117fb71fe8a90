// Under AddressSanitizer, operator new as the standard has it: a request the heap cannot meet
// throws std::bad_alloc. ASan's own operator new reports and ends the process instead (whatever
// allocator_may_return_null says), so LibraryExceptions' test of a file larger than the memory
// left (NamingInput's "not enough memory to read it") had nothing to test. This binary alone
// (library_exceptions_tests, apart from cross_tests so that no other test loses ASan's
// new/delete mismatch checks) takes its memory through ASan's malloc, which returns null when
// told to (allocator_may_return_null=1, below), and throws. Heap overflows, use after free and
// double frees are still ASan's to report: the blocks are its malloc's.

#if defined(__SANITIZE_ADDRESS__)

#include <cstdlib>
#include <new>

extern "C" const char* __asan_default_options() { return "allocator_may_return_null=1"; }

namespace {
// ASan's malloc: null when the heap cannot meet the request. At least a byte: every new gives a
// distinct address.
void* TryAllocate(std::size_t bytes) noexcept { return std::malloc(bytes == 0 ? 1 : bytes); }
void* Allocate(std::size_t bytes) {
  if (void* block = TryAllocate(bytes)) return block;
  throw std::bad_alloc();
}
}  // namespace

// The unaligned forms; the aligned ones (std::align_val_t) stay ASan's, new and delete alike.
void* operator new(std::size_t bytes) { return Allocate(bytes); }
void* operator new[](std::size_t bytes) { return Allocate(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept { return TryAllocate(bytes); }
void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept { return TryAllocate(bytes); }
void operator delete(void* block) noexcept { std::free(block); }
void operator delete[](void* block) noexcept { std::free(block); }
void operator delete(void* block, std::size_t) noexcept { std::free(block); }
void operator delete[](void* block, std::size_t) noexcept { std::free(block); }
void operator delete(void* block, const std::nothrow_t&) noexcept { std::free(block); }
void operator delete[](void* block, const std::nothrow_t&) noexcept { std::free(block); }

#endif
