#pragma once
// `arview say --scene s.yaml "text"`: a close-up video of a scene's character saying a line, for
// authoring lines (docs/speech.md, "arview say"). The line goes the way a scene's line goes in a
// session (scene_lines.h: markup, checks, synthesis on the speech queue's thread, the character's
// LayeredAnimator with its face), said on the first frame; the camera stands in front of the
// character's head, looking at it. The sound is not written (the audio module's part): what the
// result holds (the utterance: 16 kHz samples, start 0 on the video's clock) is for that.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "render/offscreen.h"
#include "speech/utterance.h"

namespace arview::app {

struct SayOptions {
  std::filesystem::path scene;
  std::string character;  // by name; empty: the scene's first
  std::string text;       // the markup
  std::string voice;      // empty: the character's `voice:` (slt by default)
  std::filesystem::path out;    // a video file (.mp4, .mkv, .avi) or a folder of PNGs
  std::filesystem::path curves;  // optional JSON: per frame, the mouth and the 15 viseme weights
  cv::Size size{640, 480};
  double fps = 30;
  double distance = 0.6;  // from the head, map units, along the character's front
  double tail_seconds = 0.5;  // after the line ends
  render::OffscreenOptions gl;
};

struct SayResult {
  int frames = 0;
  speech::Utterance utterance;
  std::string renderer;
};

// Throws CommandError-free library errors (anim::Error, speech::SpeechError, video::VideoError)
// naming the scene and the line; the output is written atomically (nothing on a failure).
SayResult RenderSpokenLine(const SayOptions& options);

}  // namespace arview::app
