#pragma once
// Issue 53's sound in a session: the lines the characters start (speech::Utterance, handed over
// on arview-render) played live through a ClipPlayer and written into the video file's audio
// track, each at the frame on which its mouth starts to move.
//
// The clock. An utterance's start_s is on the frame clock: the characters' animation time
// (FrameLog::animation_s, 0 at the first frame composed). Every frame shown tells how that clock
// maps onto the steady clock the player keeps (audio/pcm.h's Clock): shown − animation_s. The
// session keeps the median of that offset over the last 31 frames shown (one late frame does not
// move it) and converts each utterance once, when it hands it to the player: its first sample is
// heard at start_s + offset, when the frame of that animation time is shown. The player must have
// a clip its lead (100 ms) before its time, so a live session starts its lines kLiveSpeechDelay
// after their cues (SpeechOptions::start_delay_s): the cue's frame hands the sound over, the
// mouth moves on a later frame.
//
// In the video file frame k is shown at k / fps: an utterance's first sample goes at
// k / fps + (start_s − animation_s) for the first frame k written whose animation time reaches
// start_s (its own frame in a replay, where lines start on their cue's frame).
//
// Threads: OnUtterance on arview-render (it only queues the line under a lock, never waits for the
// player or the sink); OnFrameShown on the sink's thread, which owns the sink and hands the lines
// over; Finish on the session's thread once the pipeline has ended.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/pipeline/ar_pipeline.h"
#include "audio/clip_player.h"
#include "speech/utterance.h"
#include "video/sinks.h"

namespace arview::app {

// How long after its cue a line starts in a live session: the player's lead (100 ms), a period
// (10 ms), and room for the cue's frame to reach the display and the sink thread to wake (90 ms).
inline constexpr double kLiveSpeechDelay = 0.2;

// One line's sound, for the summary and stats.json.
struct LineSound {
  std::uint64_t id = 0;  // the order the session started its lines in (every character's)
  double start_s = 0;    // on the frame clock
  std::string origin;
  // Seconds since the pipeline started, the frames' clock in stats.json (captured_s + latency_ms):
  // when the first frame at or after start_s was shown, and when the first sample was heard and
  // written (the player's report; < 0: none, no player or the session ended first).
  double shown_s = -1, heard_s = -1, written_s = -1;
  bool late = false;          // the player had it after its time: it started at once
  bool in_video = false;      // written into the video's audio track
};

struct SoundReport {
  bool playing = false;  // a player was given
  std::vector<LineSound> lines;
  audio::PlayerStats player;           // when playing
  std::int64_t video_samples_dropped = 0;  // the video file's track (FrameSink::AudioSamplesDropped)
  bool video_track = false;
  double heard_in_video_s = 0;  // seconds of the dialogue's heard WAV in the video's track (AddHeardAudio)
};

class SessionSound {
 public:
  // `player`: null for no live sound. `sink`: its audio track gets the lines when it has one.
  // `fps`: the video's frame rate.
  SessionSound(audio::ClipPlayer* player, video::FrameSink& sink, double fps);

  bool active() const { return player_ != nullptr || sink_.HasAudio(); }
  // arview-render: a line has started.
  void OnUtterance(const speech::Utterance& utterance);
  // Before the pipeline starts: what the dialogue hears from a WAV (`replay --audio-in`, 16 kHz
  // mono), for the video's audio track, where its sample 0 goes at frame time 0 (the recognizer
  // hears it so) with the lines summed over it: the video then has both sides of the exchange.
  // Not played live. Nothing without a video track: the samples are copied only for one (a
  // minute of speech is 1.9 MB).
  void AddHeardAudio(const std::vector<std::int16_t>& samples);
  // The sink's thread, after the frame was written (shown).
  void OnFrameShown(const FrameLog& frame, Clock::time_point shown);
  // After the pipeline has ended.
  SoundReport Finish();

 private:
  struct Pending {
    LineSound sound;
    speech::Utterance utterance;
    bool to_player = false, to_video = false;  // still to hand over
  };
  void HandOver(Pending& line, const FrameLog& frame, Clock::time_point shown);
  double SinceStart(Clock::time_point t) const;
  void NoteDeviceFailure();

  audio::ClipPlayer* const player_;
  video::FrameSink& sink_;
  const double fps_;

  std::mutex mutex_;                // guards `incoming_` between arview-render and the sink's thread
  std::vector<Pending> incoming_;
  std::uint64_t next_id_ = 0;       // under mutex_

  // The sink's thread's (heard_ set before it starts).
  std::vector<std::int16_t> heard_;
  bool heard_written_ = false;
  std::vector<Pending> lines_;
  std::vector<std::int64_t> offsets_ns_;  // shown − animation time, the last 31 frames, a ring
  std::size_t next_offset_ = 0;
  std::int64_t frames_shown_ = 0;
  std::optional<Clock::time_point> pipeline_start_;  // from the first frame's captured_s and latency
  bool failure_noted_ = false;
};

// The summary's line about the sound ("sound: 2 lines played on time, ..."); empty without sound.
std::string SoundSummaryText(const SoundReport& report);
// stats.json's "sound".
nlohmann::ordered_json SoundJson(const SoundReport& report);

}  // namespace arview::app
