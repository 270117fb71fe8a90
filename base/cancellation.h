#pragma once
// Cancellation: one scoped handler turns SIGINT and SIGTERM into a token, and the token is
// handed to everything that runs long (child processes, the pipeline, the tracker loop, the
// recorder, V4L2 capture, readers of big files). Work polls the token at its natural steps
// (a frame, a chunk, a poll() round) and stops by throwing CancelledError; app/cli/main.cpp turns
// that into one line and exit status 128 + signal (130 for SIGINT, 143 for SIGTERM).
//
// Like COLMAP's util/ threads (Stop() sets a flag that long loops check), nothing is killed
// from inside a signal handler: the handler only stores the signal, so every writer still
// gets to remove its temporary output.

#include <atomic>
#include <csignal>
#include <memory>
#include <string>

#include "base/error.h"

namespace arview {

// Thrown by work that saw its token cancelled. what() is the user's line ("interrupted: ...").
class CancelledError : public Error {
 public:
  CancelledError(const std::string& message, int signal_number) : Error(message), signal_(signal_number) {}
  int signal_number() const { return signal_; }  // 0: cancelled by code, not by a signal
  // The shell's convention for a death by signal: 130 for SIGINT, 143 for SIGTERM.
  int exit_code() const { return 128 + (signal_ != 0 ? signal_ : SIGINT); }

 private:
  int signal_;
};

// A shared flag: copies observe and cancel the same state. A default-constructed token has
// its own state that nothing cancels unless Cancel() is called (so "no token" needs no null
// checks). Reading it is one relaxed atomic load: cheap enough for every frame.
class CancellationToken {
 public:
  CancellationToken();

  bool IsCancelled() const noexcept { return state_->cancelled.load(std::memory_order_relaxed); }
  int Signal() const noexcept { return state_->signal.load(std::memory_order_relaxed); }
  void Cancel(int signal_number = 0) const noexcept;

  // Throws CancelledError("interrupted: <what>") when cancelled.
  void ThrowIfCancelled(const std::string& what) const;
  // "interrupted by SIGINT" / "interrupted by SIGTERM" / "cancelled".
  std::string Reason() const;

  // The flag itself, for code that takes a `const std::atomic<bool>*` stop flag.
  const std::atomic<bool>* flag() const noexcept { return &state_->cancelled; }

  struct State {
    std::atomic<bool> cancelled{false};
    std::atomic<int> signal{0};
  };

 private:
  std::shared_ptr<State> state_;
  friend class ScopedSignalCancellation;
};

// While alive, SIGINT and SIGTERM cancel token() instead of killing the process (and
// interrupt blocking system calls: no SA_RESTART). A second SIGINT while the first is being
// handled kills the process the default way, for a user whose clean stop takes too long.
// The previous handlers come back on destruction. One at a time (a second live instance
// throws std::logic_error).
class ScopedSignalCancellation {
 public:
  ScopedSignalCancellation();
  ~ScopedSignalCancellation();
  ScopedSignalCancellation(const ScopedSignalCancellation&) = delete;
  ScopedSignalCancellation& operator=(const ScopedSignalCancellation&) = delete;

  const CancellationToken& token() const { return token_; }

 private:
  CancellationToken token_;
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

// "SIGINT", "SIGTERM", else "signal N".
std::string SignalName(int signal_number);

}  // namespace arview
