#include "speech/speech_queue.h"

#include <utility>

namespace arview::speech {
namespace {

std::size_t CheckedCapacity(std::size_t capacity) {
  if (capacity == 0) throw SpeechError("speech: a speech queue needs a capacity of at least 1 line");
  return capacity;
}

}  // namespace

SpeechQueue::SpeechQueue(Voice voice, std::size_t capacity)
    : synthesizer_(voice), capacity_(CheckedCapacity(capacity)),
      worker_([this](std::stop_token stop) { Run(stop); }) {}

SpeechQueue::~SpeechQueue() {
  worker_.request_stop();
  // jthread's destructor joins; condition_variable_any's wait with the stop token wakes on stop.
}

bool SpeechQueue::Submit(std::uint64_t id, std::string text) {
  {
    const std::lock_guard lock(mutex_);
    if (waiting_.size() + in_progress_ + finished_.size() >= capacity_) return false;
    waiting_.push_back({id, std::move(text)});
  }
  work_ready_.notify_one();
  return true;
}

std::optional<SpeechResult> SpeechQueue::TakeFinished() {
  const std::lock_guard lock(mutex_);
  if (finished_.empty()) return std::nullopt;
  SpeechResult result = std::move(finished_.front());
  finished_.pop_front();
  return result;
}

std::size_t SpeechQueue::Pending() const {
  const std::lock_guard lock(mutex_);
  return waiting_.size() + in_progress_ + finished_.size();
}

void SpeechQueue::Run(std::stop_token stop) {
  while (true) {
    Request request;
    {
      std::unique_lock lock(mutex_);
      if (!work_ready_.wait(lock, stop, [this] { return !waiting_.empty(); })) return;
      request = std::move(waiting_.front());
      waiting_.pop_front();
      ++in_progress_;
    }
    SpeechResult result{request.id, {}, {}};
    try {
      result.line = synthesizer_.Synthesize(request.text);
    } catch (const SpeechError& error) {
      result.error = error.what();
    }
    const std::lock_guard lock(mutex_);
    --in_progress_;
    finished_.push_back(std::move(result));
  }
}

}  // namespace arview::speech
