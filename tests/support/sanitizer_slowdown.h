#pragma once
// How much slower the code under test runs in a sanitizer build, for tests that time a whole
// command or pace frames against a thread of the code's own.

#include "base/sanitizer_build.h"

namespace arview::testing {

// Under AddressSanitizer (the asan preset) arview runs several times slower: `run` had not shown
// its first frame 3 s after its start. Under ThreadSanitizer (the tsan preset) as much or more:
// Flite synthesized a session dialogue's reply over 1 s late at load 16 (docs/reliability.md,
// "TSan on this round's threads"). Tests that time a whole command scale their waits by this;
// where an event must fall at a point of the run, they wait for that point instead (a file it
// writes: RunWithEmulatedCamera's pause_after_file).
inline constexpr double kSanitizerSlowdown = kSanitizedAllocator ? 5 : 1;

}  // namespace arview::testing
