#pragma once
// Lines synthesized ahead of when they are due, on a thread of its own (the shape of
// docs/architecture.md's threads: a member std::jthread, a stop_token, queues between threads).
//
// Threads: Submit, TakeFinished and Pending are for one caller thread (the frame or scheduling
// thread); neither blocks on synthesis: they hold the queue's lock only to move a request in or
// a result out. The worker thread alone calls Flite. The destructor stops the worker: the line
// being synthesized is finished, lines not started are dropped.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "speech/synthesizer.h"

namespace arview::speech {

struct SpeechResult {
  std::uint64_t id = 0;      // the id the line was submitted with
  SpokenLine line;           // empty when error is set
  std::string error;         // the SpeechError's line when synthesis failed, else empty
};

class SpeechQueue {
 public:
  // `capacity`: lines waiting to be synthesized plus results not yet taken, at most.
  SpeechQueue(Voice voice, std::size_t capacity);
  ~SpeechQueue();
  SpeechQueue(const SpeechQueue&) = delete;
  SpeechQueue& operator=(const SpeechQueue&) = delete;

  // Queues a line; false (nothing queued) when `capacity` lines are already waiting or done.
  bool Submit(std::uint64_t id, std::string text);
  // The oldest finished line, or none yet. Results come back in the order lines were submitted.
  std::optional<SpeechResult> TakeFinished();
  // Lines submitted whose results have not been taken.
  std::size_t Pending() const;

 private:
  struct Request {
    std::uint64_t id;
    std::string text;
  };
  void Run(std::stop_token stop);

  const Synthesizer synthesizer_;
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable_any work_ready_;
  std::deque<Request> waiting_;
  std::size_t in_progress_ = 0;
  std::deque<SpeechResult> finished_;
  std::jthread worker_;  // last: started once everything it uses exists
};

}  // namespace arview::speech
