#include "base/cancellation.h"

#include <signal.h>
#include <unistd.h>

#include <stdexcept>

namespace arview {

namespace {

// The state the live handler cancels. A raw pointer in a lock-free atomic: the only thing a
// signal handler may touch. The ScopedSignalCancellation keeps the state alive while it is set.
std::atomic<CancellationToken::State*> g_target{nullptr};
static_assert(std::atomic<CancellationToken::State*>::is_always_lock_free);
static_assert(std::atomic<bool>::is_always_lock_free);
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void OnCancelSignal(int signal_number) {
  CancellationToken::State* state = g_target.load();
  if (state == nullptr) return;
  if (signal_number == SIGINT && state->cancelled.load()) {
    // Second Ctrl-C: the user does not want to wait for the clean stop.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    ::sigaction(SIGINT, &dfl, nullptr);
    ::raise(SIGINT);
    return;
  }
  int expected = 0;
  state->signal.compare_exchange_strong(expected, signal_number);
  state->cancelled.store(true);
}

}  // namespace

CancellationToken::CancellationToken() : state_(std::make_shared<State>()) {}

void CancellationToken::Cancel(int signal_number) const noexcept {
  int expected = 0;
  if (signal_number != 0) state_->signal.compare_exchange_strong(expected, signal_number);
  state_->cancelled.store(true);
}

std::string CancellationToken::Reason() const {
  const int s = Signal();
  return s == 0 ? "cancelled" : "interrupted by " + SignalName(s);
}

void CancellationToken::ThrowIfCancelled(const std::string& what) const {
  if (IsCancelled()) throw CancelledError("interrupted (" + SignalName(Signal()) + "): " + what, Signal());
}

std::string SignalName(int signal_number) {
  switch (signal_number) {
    case 0: return "cancelled";
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "signal " + std::to_string(signal_number);
  }
}

ScopedSignalCancellation::ScopedSignalCancellation() {
  CancellationToken::State* expected = nullptr;
  if (!g_target.compare_exchange_strong(expected, token_.state_.get())) {
    throw std::logic_error("ScopedSignalCancellation: another one is already installed");
  }
  struct sigaction sa {};
  sa.sa_handler = OnCancelSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking poll()/read() returns EINTR and sees the token
  ::sigaction(SIGINT, &sa, &old_int_);
  ::sigaction(SIGTERM, &sa, &old_term_);
}

ScopedSignalCancellation::~ScopedSignalCancellation() {
  ::sigaction(SIGINT, &old_int_, nullptr);
  ::sigaction(SIGTERM, &old_term_, nullptr);
  g_target.store(nullptr);
}

}  // namespace arview
