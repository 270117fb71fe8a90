#include "tracker/worker.h"

#include <pthread.h>

#include "base/thread_priority.h"

namespace arview::tracker {

Worker::Worker(int nice_increment)
    : thread_([this, nice_increment](std::stop_token stop) { Run(stop, nice_increment); }) {}

Worker::~Worker() {
  std::lock_guard lock(mutex_);
  waiting_ = nullptr;  // destroys its packaged_task: the future sees a broken promise
}  // then thread_'s destructor asks the thread to stop and joins it

void Worker::Post(std::function<void()> job) {
  std::function<void()> dropped;  // destroyed outside the lock
  {
    std::lock_guard lock(mutex_);
    dropped = std::move(waiting_);
    waiting_ = std::move(job);
  }
  wake_.notify_one();
}

bool Worker::Busy() const {
  std::lock_guard lock(mutex_);
  return running_ || waiting_;
}

void Worker::Run(std::stop_token stop, int nice_increment) {
  pthread_setname_np(pthread_self(), "arview-trackwk");  // shown by top -H
  LowerCurrentThreadPriority(nice_increment);
  std::unique_lock lock(mutex_);
  // Returns false, nothing waiting, once a stop is asked.
  while (wake_.wait(lock, stop, [this] { return waiting_ != nullptr; })) {
    std::function<void()> job = std::move(waiting_);
    waiting_ = nullptr;
    running_ = true;
    lock.unlock();
    job();
    job = nullptr;
    lock.lock();
    running_ = false;
  }
}

}  // namespace arview::tracker
