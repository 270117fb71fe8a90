#pragma once
// A source of 16 kHz mono blocks delivered to a callback on a thread of the source's own: the
// ALSA microphone (audio/alsa_capture.h) or a WAV file paced by a clock (audio/wav_source.h),
// behind one interface so that recognition runs the same on both.
//
// Threads (docs/architecture.md's shape): Start, RequestStop, IsTerminated and Join are for the
// owner's thread. on_block and on_end run on the source's thread, one call at a time, and must
// not block for long (a recognizer queues the block and returns): the source holds no lock while
// it calls them. After Join (or the destructor) returns, no callback runs again.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stop_token>
#include <string>
#include <thread>

#include "audio/pcm.h"

namespace arview::audio {

struct CapturedBlock {
  std::span<const std::int16_t> samples;  // 16 kHz mono; valid only during the call
  std::int64_t first_sample = 0;          // index of samples[0] since the source started
  TimePoint heard_at;                     // when samples[0] was heard, on the source's clock
};

// Why a source ended: the end of its input (error empty), or a failure, one line naming the
// device or file and what happened (a microphone unplugged: the owner prints it and goes on
// without listening).
struct SourceEnd {
  std::string error;
  std::int64_t samples_delivered = 0;
};

using BlockCallback = std::function<void(const CapturedBlock&)>;
using EndCallback = std::function<void(const SourceEnd&)>;

class AudioSource {
 public:
  virtual ~AudioSource();
  AudioSource(const AudioSource&) = delete;
  AudioSource& operator=(const AudioSource&) = delete;

  // Starts the thread; on_block for each block in order, then on_end exactly once (also after
  // a stop). Starting twice is an AudioError.
  void Start(BlockCallback on_block, EndCallback on_end);
  void RequestStop();
  // True once the thread has called on_end (or was never started).
  bool IsTerminated() const { return terminated_.load(); }
  void Join();

 protected:
  // `thread_name`: at most 15 characters (the kernel's limit), shown by top -H.
  AudioSource(std::string thread_name, std::size_t block_samples);

  // What the thread reads next: fills the front of `block` and returns how many samples it put
  // there (0: the input ended) and when the first was heard. Throws AudioError on a failure.
  struct Read {
    std::size_t count = 0;
    TimePoint heard_at;
  };
  virtual Read ReadBlock(std::span<std::int16_t> block, const std::stop_token& stop) = 0;

  // Called last, once, on the source's thread after its final read (closes a device).
  virtual void Finish() {}

  // Joins the thread: a derived class's destructor calls it first, so that ReadBlock never runs
  // on a half-destroyed object.
  void StopAndJoin();

 private:
  void Run(const std::stop_token& stop, const BlockCallback& on_block, const EndCallback& on_end);

  const std::string thread_name_;
  const std::size_t block_samples_;
  std::atomic<bool> terminated_{true};
  std::jthread thread_;
};

}  // namespace arview::audio
