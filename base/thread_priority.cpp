#include "base/thread_priority.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>

namespace arview {
namespace {

id_t CurrentThreadId() { return static_cast<id_t>(syscall(SYS_gettid)); }

}  // namespace

std::string RaiseCurrentThreadForTiming(int realtime_priority) {
  sched_param param{};
  param.sched_priority = std::clamp(realtime_priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO));
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0) {
    return "real-time (SCHED_FIFO " + std::to_string(param.sched_priority) + ")";
  }
  constexpr int kRaisedNice = -10;
  const id_t tid = CurrentThreadId();
  if (getpriority(PRIO_PROCESS, tid) <= kRaisedNice) return "nice " + std::to_string(getpriority(PRIO_PROCESS, tid));
  if (setpriority(PRIO_PROCESS, tid, kRaisedNice) == 0) return "nice " + std::to_string(kRaisedNice);
  return "normal priority (real-time not permitted)";
}

void LowerCurrentThreadPriority(int nice_increment) {
  const id_t tid = CurrentThreadId();
  (void)setpriority(PRIO_PROCESS, tid, getpriority(PRIO_PROCESS, tid) + nice_increment);
}

}  // namespace arview
