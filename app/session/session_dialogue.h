#pragma once
// A session's dialogue (issue 54, `run --dialogue d.yaml [--mic DEVICE]`, `replay --dialogue
// d.yaml --audio-in talk.wav`), set up at load: the dialogue file read, the recognizer made with
// every phrase the dialogue can hear (an unknown word is said before the first frame), the audio
// that feeds it (the microphone, or a WAV paced by the frame clock), the replies' voice, and the
// first character's CharacterDialogue (app/pipeline/character_dialogue.h) attached to its animator.
//
// Threads: the constructor, Start and Stop are the session's main thread. The audio source's
// thread pushes into the recognizer (arview-mic or arview-wavin); the recognizer decodes on
// arview-listen; the replies are synthesized on their SpeechQueue's thread; the render thread
// drives the CharacterDialogue.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "anim_authoring/character_builder.h"
#include "app/pipeline/character_dialogue.h"
#include "app/pipeline/layered_animator.h"
#include "audio/audio_source.h"
#include "listen/recognizer.h"
#include "speech/utterance.h"

namespace arview::app {

struct DialogueSessionOptions {
  std::filesystem::path dialogue_file;  // empty: no dialogue
  std::string mic_device;               // `run --mic`: an ALSA capture device; empty: none
  std::filesystem::path audio_in;       // `replay --audio-in`: a WAV paced by the frame clock
  std::uint64_t seed = 0;               // the choice between machines of equal priority
  // Voice activity's end of speech: non-speech frames (10 ms) before an utterance ends. Fewer
  // answer sooner but split a phrase at a pause that long (docs/listen.md, "Modes").
  int end_of_speech_frames = 20;
  // The recognizer's confidence gate (listen::RecognizerOptions::min_confidence).
  double min_confidence = listen::RecognizerOptions{}.min_confidence;
  // `--push-to-talk`: the recognizer hears only between two presses of the window's key
  // (kPushToTalkKey, TogglePushToTalk); otherwise it listens by voice activity.
  bool push_to_talk = false;
  bool enabled() const { return !dialogue_file.empty(); }
};

class SessionDialogue {
 public:
  // Throws the dialogue's DialogueError, the recognizer's ListenError, the audio's AudioError (a
  // microphone that cannot be opened, a WAV that cannot be read or converted) or
  // speech::SpeechError, each one line. `animator` is the first character's; a CharacterSpeech
  // without lines is given to it when it has none. `on_line` prints a line for the user (a
  // microphone gone mid-session), from the audio source's thread.
  SessionDialogue(const DialogueSessionOptions& options, const authoring::AnimatedCharacter& character,
                  LayeredAnimator& animator, std::function<void(const speech::Utterance&)> on_utterance,
                  std::function<void(const std::string&)> on_line);
  ~SessionDialogue();
  SessionDialogue(const SessionDialogue&) = delete;
  SessionDialogue& operator=(const SessionDialogue&) = delete;

  // The audio's thread: just before the pipeline's frames.
  void Start();
  // Stops the audio and the recognizer's input; after the pipeline has ended.
  void Stop();
  // Push-to-talk's key (the window's key handler, arview-sink; any thread): opens listening, or
  // closes it and the utterance is decoded. Whether listening is now open; false without
  // push-to-talk or a recognizer.
  bool TogglePushToTalk();
  // What the user should be told at load (a gesture the character lacks, ...), one line each.
  const std::vector<std::string>& load_notes() const { return load_notes_; }
  // The microphone's end, when it failed (empty otherwise); after Stop.
  std::string audio_error() const;
  // `--audio-in`'s samples as the recognizer hears them (16 kHz mono, sample 0 at frame time 0);
  // empty for the microphone or without listening.
  const std::vector<std::int16_t>& heard_samples() const { return heard_samples_; }

 private:
  std::unique_ptr<listen::Recognizer> recognizer_;
  std::unique_ptr<FramePacingClock> frame_clock_;
  std::unique_ptr<audio::AudioSource> source_;
  std::vector<std::int16_t> heard_samples_;
  std::vector<std::string> load_notes_;
  std::function<void(const std::string&)> on_line_;
  CharacterDialogue* dialogue_ = nullptr;  // owned by the animator
  mutable std::mutex mutex_;
  std::string audio_error_;
  // The microphone's clock: the latest block's first sample and when it was heard (mutex_).
  std::int64_t block_first_ = 0;
  audio::TimePoint block_heard_{};
  bool started_ = false;
};

}  // namespace arview::app
