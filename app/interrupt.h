#pragma once
// Ctrl-C for long commands: the first SIGINT asks the work to stop cleanly (the flag), a second
// one kills the process the default way.

#include <atomic>
#include <csignal>

namespace arview::app {

class InterruptFlag {
 public:
  InterruptFlag() {
    Flag().store(false);
    previous_ = std::signal(SIGINT, &InterruptFlag::Handle);
  }
  ~InterruptFlag() { std::signal(SIGINT, previous_); }
  InterruptFlag(const InterruptFlag&) = delete;
  InterruptFlag& operator=(const InterruptFlag&) = delete;

  const std::atomic<bool>* flag() const { return &Flag(); }
  bool raised() const { return Flag().load(); }

 private:
  static std::atomic<bool>& Flag() {
    static std::atomic<bool> flag{false};
    return flag;
  }
  static void Handle(int) {
    Flag().store(true);
    std::signal(SIGINT, SIG_DFL);
  }
  void (*previous_)(int) = SIG_DFL;
};

}  // namespace arview::app
