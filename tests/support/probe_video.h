#pragma once
// What ffprobe reads from a video the tests' arview wrote: a stream's duration, the frames that
// decode to its end. ffprobe runs in a process of its own: libavcodec's frame threads hand frames
// over with atomics compiled without TSan, so decoding in a test's process gave TSan reports in
// FFmpeg (tests/live_faults_test.cpp under the tsan preset).

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/support/run_command.h"

namespace arview::testing {

// ffprobe's one value `entry` (e.g. stream=duration) of the first stream of `type` ("video",
// "audio") in `video`, with `extra` options before it; "" when ffprobe failed or printed none.
// The answer goes through a file in `dir`.
inline std::string ProbeFirstStream(const std::filesystem::path& video, const std::string& type,
                                    const std::string& entry, const std::filesystem::path& dir,
                                    const std::string& extra = "") {
  const std::filesystem::path answer = dir / ("probe_" + type + ".txt");
  const std::string cmd = "ffprobe -v error " + extra + " -select_streams " + type.substr(0, 1) +
                          ":0 -show_entries " + entry + " -of csv=p=0 " + ShellQuote(video.string()) + " >" +
                          ShellQuote(answer.string());
  if (std::system(cmd.c_str()) != 0) return "";
  std::string text = ReadWholeFile(answer.string());
  while (!text.empty() && (text.back() == '\n' || text.back() == ',')) text.pop_back();
  return text;
}

// The duration in seconds of the first stream of `type` ("video", "audio"); < 0: none.
inline double StreamDuration(const std::filesystem::path& video, const std::string& type,
                             const std::filesystem::path& dir) {
  const std::string text = ProbeFirstStream(video, type, "stream=duration", dir);
  return text.empty() || text == "N/A" ? -1 : std::stod(text);
}

// The frames of the first video stream that decode, to its end; -1: ffprobe could not read it.
inline int DecodedVideoFrames(const std::filesystem::path& video, const std::filesystem::path& dir) {
  const std::string text = ProbeFirstStream(video, "video", "stream=nb_read_frames", dir, "-count_frames");
  return text.empty() || text == "N/A" ? -1 : std::stoi(text);
}

}  // namespace arview::testing
