#include "audio/audio_source.h"

#include <pthread.h>

#include <exception>
#include <vector>

#include "audio/audio_error.h"

namespace arview::audio {

AudioSource::AudioSource(std::string thread_name, std::size_t block_samples)
    : thread_name_(std::move(thread_name)), block_samples_(block_samples) {
  if (block_samples_ == 0) throw AudioError("audio: a source's block must hold at least one sample");
}

AudioSource::~AudioSource() { StopAndJoin(); }

void AudioSource::Start(BlockCallback on_block, EndCallback on_end) {
  if (thread_.joinable()) throw AudioError("audio: the source '" + thread_name_ + "' was already started");
  terminated_ = false;
  thread_ = std::jthread([this, on_block = std::move(on_block), on_end = std::move(on_end)](std::stop_token stop) {
    Run(stop, on_block, on_end);
  });
}

void AudioSource::RequestStop() { thread_.request_stop(); }

void AudioSource::Join() {
  if (thread_.joinable()) thread_.join();
}

void AudioSource::StopAndJoin() {
  RequestStop();
  Join();
}

void AudioSource::Run(const std::stop_token& stop, const BlockCallback& on_block, const EndCallback& on_end) {
  pthread_setname_np(pthread_self(), thread_name_.c_str());
  std::vector<std::int16_t> block(block_samples_);
  SourceEnd end;
  try {
    while (!stop.stop_requested()) {
      const Read read = ReadBlock(block, stop);
      if (read.count == 0 || stop.stop_requested()) break;
      on_block(CapturedBlock{std::span<const std::int16_t>(block.data(), read.count), end.samples_delivered, read.heard_at});
      end.samples_delivered += static_cast<std::int64_t>(read.count);
    }
  } catch (const std::exception& error) {
    // A device's AudioError, or whatever a callback threw: the line ends the source, not the
    // process (an exception must not leave a std::jthread).
    end.error = error.what();
  }
  Finish();
  on_end(end);
  terminated_ = true;
}

}  // namespace arview::audio
