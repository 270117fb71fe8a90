#include "tests/gl_fence/signal_stall.h"

#include <dlfcn.h>
#include <pthread.h>
#include <sys/prctl.h>
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cstring>

// Interposed on the pthread calls of the whole test process (the executable exports them, so
// that Mesa's llvmpipe, loaded with dlopen, binds to these). Everything here must work before
// main and inside any thread: no allocation, no C++ statics with constructors.

namespace {

using MutexFn = int (*)(pthread_mutex_t*);
using CondFn = int (*)(pthread_cond_t*);

std::atomic<bool> g_armed{false};
std::atomic<long> g_destroyed_while_held{0};
std::atomic<long> g_signaller_stalls{0};

// The condition variable this thread signalled last, until its next mutex unlock: Mesa's
// lp_fence_signal and pipe_semaphore_signal both signal the condition that follows their mutex
// in one struct ({mtx_t; cnd_t;}), then unlock that mutex.
thread_local const void* t_signalled = nullptr;

std::atomic<MutexFn> g_real_unlock{nullptr}, g_real_destroy{nullptr};
std::atomic<CondFn> g_real_signal{nullptr}, g_real_broadcast{nullptr};

// libc's `name`, looked up once into `slot`.
template <typename Fn>
Fn Real(std::atomic<Fn>& slot, const char* name) {
  Fn fn = slot.load(std::memory_order_acquire);
  if (fn == nullptr) slot.store(fn = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name)), std::memory_order_release);
  return fn;
}

// llvmpipe's struct lp_fence holds {mtx_t mutex; cnd_t signalled; bool issued; unsigned rank;
// unsigned count;} in this order (Mesa 22.3, Debian 12's, as the crash's core dump shows, and
// Mesa's current source): a fence whose count has reached its rank is
// what lp_fence_signal leaves just before it unlocks. Read past the mutex and its condition
// variable, so not through ASan's eyes (a pipe_semaphore ends sooner).
__attribute__((no_sanitize("address"))) bool LooksLikeAFenceJustSignalled(const pthread_mutex_t* mutex) {
  const char* after = reinterpret_cast<const char*>(mutex) + sizeof(pthread_mutex_t) + sizeof(pthread_cond_t);
  unsigned char issued = 0;
  unsigned rank = 0, count = 0;
  std::memcpy(&issued, after, 1);
  std::memcpy(&rank, after + 4, sizeof rank);
  std::memcpy(&count, after + 8, sizeof count);
  return issued == 1 && rank >= 1 && rank <= 64 && count == rank;
}

bool OnLlvmpipeThread() {
  char name[16] = {0};
  prctl(PR_GET_NAME, name, 0, 0, 0);
  return std::strncmp(name, "llvmpipe", 8) == 0;
}

void SleepMs(long ms) {
  timespec t{ms / 1000, (ms % 1000) * 1000000};
  while (nanosleep(&t, &t) != 0 && errno == EINTR) {
  }
}

// Whether `mutex` is the one right before the condition this thread just signalled.
bool UnlocksAfterItsSignal(const pthread_mutex_t* mutex) {
  const void* signalled = t_signalled;
  t_signalled = nullptr;
  return signalled != nullptr && signalled == reinterpret_cast<const char*>(mutex) + sizeof(pthread_mutex_t);
}

}  // namespace

extern "C" {

int pthread_cond_signal(pthread_cond_t* cond) {
  const int result = Real(g_real_signal, "pthread_cond_signal")(cond);
  t_signalled = cond;
  return result;
}

int pthread_cond_broadcast(pthread_cond_t* cond) {
  const int result = Real(g_real_broadcast, "pthread_cond_broadcast")(cond);
  t_signalled = cond;
  return result;
}

int pthread_mutex_unlock(pthread_mutex_t* mutex) {
  const MutexFn unlock = Real(g_real_unlock, "pthread_mutex_unlock");
  if (!g_armed.load(std::memory_order_relaxed) || !UnlocksAfterItsSignal(mutex)) return unlock(mutex);
  if (!OnLlvmpipeThread()) {
    // The drawing thread after it woke the rasterizer (pipe_semaphore_signal): descheduled for a
    // moment, so that the rasterizer finishes the scene before the drawing thread looks at it.
    const int result = unlock(mutex);
    SleepMs(arview::testing::kKickerStallMs);
    return result;
  }
  if (LooksLikeAFenceJustSignalled(mutex)) {
    // A rasterizer thread that signalled a fence (its count now equals its rank), descheduled
    // before it lets the fence's mutex go, as on a loaded machine.
    ++g_signaller_stalls;
    SleepMs(arview::testing::kSignallerStallMs);
  }
  return unlock(mutex);
}

int pthread_mutex_destroy(pthread_mutex_t* mutex) {
  const int result = Real(g_real_destroy, "pthread_mutex_destroy")(mutex);
  // glibc refuses to destroy a mutex that a thread holds; Mesa frees the memory anyway, and the
  // holder's unlock then writes into freed memory.
  if (result == EBUSY) ++g_destroyed_while_held;
  return result;
}

}  // extern "C"

namespace arview::testing {

void ArmSignalStall(bool armed) { g_armed.store(armed); }
long MutexesDestroyedWhileHeld() { return g_destroyed_while_held.load(); }
long SignallerStalls() { return g_signaller_stalls.load(); }

}  // namespace arview::testing
