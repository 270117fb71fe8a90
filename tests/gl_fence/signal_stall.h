#pragma once
// Widens, on purpose, the window of a race inside Mesa's llvmpipe (docs/reliability.md, "The
// live crash"), and detects when it is hit. Linked into its own test executable only: it
// replaces pthread_mutex_unlock, pthread_mutex_destroy, pthread_cond_signal and
// pthread_cond_broadcast for the whole process.
//
// Armed, a thread that signals a condition variable and then unlocks the mutex stored just before
// it (Mesa's {mtx_t; cnd_t;} pairs: lp_fence_signal, pipe_semaphore_signal) is stalled there: a
// llvmpipe rasterizer thread for kSignallerStallMs before the unlock (the fence's count already
// equals its rank), any other thread for kKickerStallMs after it (the drawing thread, having woken
// the rasterizer). Every pthread_mutex_destroy that glibc refuses with EBUSY (the mutex still
// held) is counted: llvmpipe's lp_fence_destroy ignores that answer and frees the fence, and the
// holder's unlock then writes a zero into freed memory.

namespace arview::testing {

inline constexpr long kSignallerStallMs = 20;
inline constexpr long kKickerStallMs = 5;

void ArmSignalStall(bool armed);
long MutexesDestroyedWhileHeld();
long SignallerStalls();

}  // namespace arview::testing
