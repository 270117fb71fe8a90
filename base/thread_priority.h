#pragma once
// Scheduling a thread asks for itself. On Linux a thread's policy and nice value are its own
// (set on its thread id), so each of our threads sets them where it starts.

#include <string>

namespace arview {

// For a thread that must wake on time and does little when it does: the sound's player and
// capture, whose device runs dry (an audible gap) when they wake late. SCHED_FIFO at
// `realtime_priority` (1-99) where the process may (root, CAP_SYS_NICE, or an RLIMIT_RTPRIO at
// least that high: a login's /etc/security/limits.conf `@audio - rtprio 20`, as JACK's users
// set), else nice -10 where it may, else the thread stays as it was. A real-time thread preempts
// every ordinary one, so it must block between its short bursts of work, as the sound threads do
// on their devices and clocks. Returns what the thread got, in words for the session's summary:
// "real-time (SCHED_FIFO 20)", "nice -10", or "normal priority (real-time not permitted)".
std::string RaiseCurrentThreadForTiming(int realtime_priority);

// Lowers the calling thread's priority by `nice_increment` (best effort: a refusal costs only
// the priority).
void LowerCurrentThreadPriority(int nice_increment);

}  // namespace arview
