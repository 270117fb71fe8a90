// A target with planted faults, for fuzz/driver_selftest.sh: it checks that the standalone
// driver (standalone_driver.cpp) reports each kind of finding, keeps the input that caused it
// and that the kept input reproduces it. ARVIEW_FUZZ_SELFTEST picks the fault, met by every
// input other than the seed "seed" (so the first mutation meets it):
//   throw     an exception escapes the target
//   segv      a write through a null pointer
//   abort     std::abort()
//   hang      an endless loop
//   overflow  a read one byte past the input (a report under AddressSanitizer only)
//   signed    a signed integer overflow (a report under UndefinedBehaviorSanitizer only)
//   log       no fault: each input's hash is appended to $ARVIEW_FUZZ_SELFTEST_LOG
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "base/hash.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string mode = [] {
    const char* m = std::getenv("ARVIEW_FUZZ_SELFTEST");
    return std::string(m ? m : "");
  }();
  if (mode == "log") {
    const std::uint64_t hash = arview::Fnv1aOf(data, size);
    static FILE* log = std::fopen(std::getenv("ARVIEW_FUZZ_SELFTEST_LOG"), "w");
    std::fprintf(log, "%016llx %zu\n", static_cast<unsigned long long>(hash), size);
    std::fflush(log);
    return 0;
  }
  if (size == 4 && std::memcmp(data, "seed", 4) == 0) return 0;
  if (mode == "throw") throw std::runtime_error("planted exception");
  if (mode == "segv") {
    volatile int* volatile null = nullptr;
    *null = 1;
  }
  if (mode == "abort") std::abort();
  if (mode == "hang") {
    volatile unsigned long spins = 0;
    for (;;) spins = spins + 1;
  }
  if (mode == "overflow") {
    volatile std::uint8_t past = data[size];
    (void)past;
  }
  if (mode == "signed") {
    volatile int big = INT_MAX;
    volatile int sum = big + static_cast<int>(size + 1);
    (void)sum;
  }
  return 0;
}
