#pragma once
// One line as a session says it, for whatever plays or records the sound (issue 53's audio half:
// ALSA output, the MP4's audio track): the line's 16 kHz samples and when its first sample is
// due on the session's frame clock.

#include <cstdint>
#include <memory>
#include <string>

#include "speech/synthesizer.h"

namespace arview::speech {

struct Utterance {
  std::uint64_t sequence = 0;  // 0, 1, 2, ... in the order the session started them
  // When sample 0 is due, seconds on the session's frame clock: the animation time, which is 0 at
  // the first frame composed (the output video's first frame) and runs with the frames'
  // timestamps from there (app/pipeline/pipeline_stages.cpp, RenderStage::AnimateAndCompose).
  double start_s = 0;
  std::shared_ptr<const SpokenLine> line;  // samples: mono int16 at SpokenLine::kSampleRate (16 kHz)
  std::string character;  // the scene character's name
  std::string origin;     // where the line was written ("scene.yaml:14")
};

}  // namespace arview::speech
