// The stall interposer (signal_stall.h) as a library to preload into `arview` itself
// (LD_PRELOAD), armed from the start; its counts are printed when the process exits normally.
// docs/reliability.md, "The live crash, found", has the replay it is used with.

#include <cstdio>

#include "tests/gl_fence/signal_stall.h"

namespace {

__attribute__((constructor)) void Arm() { arview::testing::ArmSignalStall(true); }

__attribute__((destructor)) void Report() {
  std::fprintf(stderr, "signal_stall: %ld fence signals stalled, %ld fence mutexes destroyed while held\n",
               arview::testing::SignallerStalls(), arview::testing::MutexesDestroyedWhileHeld());
}

}  // namespace
