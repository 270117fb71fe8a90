#pragma once
// One background thread, at a lower scheduling priority than its owner, that runs one job at a
// time: the tracker's SIFT extraction and relocalization for a live source, so that the tracking
// thread never waits for them (docs/tracker.md, "The tracking worker").

#include <condition_variable>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <stop_token>
#include <thread>

namespace arview::tracker {

// Which thread may touch what: Submit and Busy from the owner's thread (or any: they lock);
// a job runs on the worker thread alone, and what it touches besides its own copies is its
// submitter's rule to state (tracker/tracking_worker.h).
class Worker {
 public:
  // nice_increment: added to the thread's nice value (Linux schedules threads one by one), so
  // that on a machine with fewer cores than busy threads the worker yields to the pipeline's.
  explicit Worker(int nice_increment = 10);
  // Finishes the running job; a waiting one is dropped (its future reports a broken promise).
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Runs `job` once the running job (if any) is done. A job submitted earlier that has not
  // started yet is dropped: only the newest frame is worth the work. The future is ready when
  // the job has run; waiting on it is the caller's choice.
  template <typename Result>
  std::future<Result> Submit(std::function<Result()> job) {
    auto task = std::make_shared<std::packaged_task<Result()>>(std::move(job));
    std::future<Result> result = task->get_future();
    Post([task] { (*task)(); });
    return result;
  }
  // Whether a job is running or waiting.
  bool Busy() const;

 private:
  void Post(std::function<void()> job);
  void Run(std::stop_token stop, int nice_increment);

  mutable std::mutex mutex_;
  std::condition_variable_any wake_;  // waits on the stop token too
  std::function<void()> waiting_;  // empty: none
  bool running_ = false;
  // Last: started once the members above exist; its destructor asks it to stop and joins it
  // before they go.
  std::jthread thread_;
};

}  // namespace arview::tracker
