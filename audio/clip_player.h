#pragma once
// The sound out: timed clips played through ALSA on the thread `arview-play`, never on the frame
// path. A clip is 16 kHz mono samples and the time, on the steady clock (audio/pcm.h's Clock),
// at which its first sample must be heard: a line of speech due when the mouth starts to move.
//
// How a clip is heard on time: the player keeps the device fed with silence and writes one
// period (10 ms) at a time, keeping `lead` (100 ms) queued. Before each write it asks
// snd_pcm_delay how many frames are queued ahead of the next one: that frame will be heard at
// now + delay / 16000 s. A clip whose time falls in the period being written starts at the
// sample that will be heard at its time (to the sample); a clip whose time has passed starts at
// once and is reported late. Clips that overlap are mixed (summed, saturating).
//
// Devices that do not pace their writes (ALSA's `null`, the `file` plugin over it: the tests'
// emulated output) report no delay; the player then keeps its own count of what it queued
// against the clock and never runs more than `lead` ahead of real time, so that the file
// receives each sample when a sound card would have played it.
//
// Underruns: ALSA's (a write that found the device starved, EPIPE: recovered and counted), and
// for a device that reports no delay, the player's own count of the queue running dry (it woke
// too late to write the next period in time).
//
// The player's thread asks for real-time scheduling (base/thread_priority.h), falling back to a
// raised nice value, so that compilers and the frame path on a loaded machine do not make it
// wake late; PlayerStats::scheduling says what it got.
//
// Threads: Play, Stats and TakeReports may be called from any thread; they hold the player's
// lock only to move a clip in or a copy out, never across a device call. A device failure ends
// the thread; Stats().error says why (one line), later clips are dropped and counted.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "audio/pcm.h"

namespace arview::audio {

struct OpenedPcm;  // audio/alsa_pcm.h: ALSA's headers stay out of the users' translation units

struct TimedClip {
  std::uint64_t id = 0;               // the caller's, echoed in the clip's report
  std::vector<std::int16_t> samples;  // 16 kHz mono
  TimePoint start;                    // when samples[0] must be heard
};

struct PlayerOptions {
  std::string device = "default";
  std::chrono::milliseconds period{10};  // one write
  // Queued ahead of the clock: the margin for a late wake-up (docs/audio.md: 60 ms underran once in
  // two minutes on the loaded build machine). Clips are placed by their time whatever the lead;
  // a clip must be given at least this long before its time not to start late.
  std::chrono::milliseconds lead{100};
};

// When a clip's first sample went out.
struct ClipReport {
  std::uint64_t id = 0;
  TimePoint scheduled;  // the clip's start
  TimePoint heard;      // when its first sample is heard, from snd_pcm_delay at its write
  TimePoint written;    // when the write that held its first sample returned
  bool late = false;    // its time had passed when it could be written: it started at once
};

struct PlayerStats {
  std::int64_t frames_written = 0;  // samples sent to the device, silence included
  std::int64_t underruns = 0;
  // Of those, the ones while a clip was sounding: a gap heard in the speech. The others fell in
  // silence, which a starved device only lengthens, but they show the thread woke late.
  std::int64_t underruns_in_clips = 0;
  std::int64_t clips_played = 0;    // clips whose last sample was written
  std::int64_t clips_late = 0;
  std::int64_t clips_dropped = 0;   // played after a device failure
  // The least audio queued ahead of the clock found before a write once the queue first reached the lead:
  // how close the player came to an underrun (the lead less its worst late wake-up; negative:
  // the queue ran dry).
  Clock::duration least_queued = Clock::duration::max();
  std::string error;                // the device's failure, one line; empty while it works
  std::string scheduling;           // what the player's thread got: "real-time (SCHED_FIFO 20)", "nice -10", ...
};

class ClipPlayer {
 public:
  // Opens the device and starts the thread; an AudioError naming the device when it cannot.
  explicit ClipPlayer(const PlayerOptions& options);
  ~ClipPlayer();  // stops: clips still queued are not played
  ClipPlayer(const ClipPlayer&) = delete;
  ClipPlayer& operator=(const ClipPlayer&) = delete;

  // Queues a clip (empty clips are ignored). Never waits for the device.
  void Play(TimedClip clip);
  PlayerStats Stats() const;
  // The reports of clips whose first sample has been written since the last call, in that order.
  std::vector<ClipReport> TakeReports();
  // Whether every clip queued so far has been written to the end (or dropped).
  bool Idle() const;

  void RequestStop() { thread_.request_stop(); }
  bool IsTerminated() const { return terminated_.load(); }
  void Join();

 private:
  struct Active;  // a clip being written: its samples and the stream position of its first
  void Run(const std::stop_token& stop);
  // `queued`: how much was queued ahead of the clock before this write (negative: ran dry); none
  // while the queue is first filled up to the lead.
  void WritePeriod(std::vector<Active>& active, std::int64_t position, TimePoint heard_next,
                   std::optional<Clock::duration> queued, std::vector<std::int16_t>& period);
  static bool ClipSoundingBefore(const std::vector<Active>& active, std::int64_t position);

  const std::string device_;
  std::unique_ptr<OpenedPcm> pcm_;
  const std::int64_t period_frames_;
  const Clock::duration lead_;

  mutable std::mutex mutex_;
  std::condition_variable_any wake_;  // a stop request ends the player's sleeps early
  std::deque<TimedClip> incoming_;
  std::vector<ClipReport> reports_;
  PlayerStats stats_;
  std::int64_t clips_in_flight_ = 0;  // queued or active

  std::atomic<bool> terminated_{false};
  std::jthread thread_;  // last: started once everything it uses exists
};

}  // namespace arview::audio
