// Issue 53's sound end to end: the lines' audio in the videos of `say` and `replay` (an AAC track
// as long as the video, in step with the mouth: cross-correlation of the mouth's opening with the
// audio's envelope), and live through the emulated ALSA speaker (tests/support/emulated.asoundrc):
// `arview run` on the emulated camera plays each line's first sample with the frame on which its
// mouth starts to move, with no underrun. ARVIEW_SPEECH_SOAK_SECONDS sets the live session's
// length (10 s here; 120 for the two-minute run of docs/speech.md).

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "recordings/recording.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/emulated_sound.h"
#include "tests/support/graffiti_map.h"
#include "tests/support/probe_video.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::ShellQuote;
using testing::StreamDuration;

constexpr int kRate = 16000;

fs::path TempFolder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_speech_sound_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The video's audio track decoded by FFmpeg's command line (not arview's code) to 16 kHz mono.
std::vector<std::int16_t> DecodeAudio(const fs::path& video, const fs::path& dir) {
  const fs::path raw = dir / "decoded.raw";
  const std::string cmd = "ffmpeg -v error -y -i " + ShellQuote(video.string()) + " -f s16le -ac 1 -ar 16000 " +
                          ShellQuote(raw.string());
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string bytes = testing::ReadWholeFile(raw.string());
  std::vector<std::int16_t> samples(bytes.size() / 2);
  std::memcpy(samples.data(), bytes.data(), samples.size() * 2);
  return samples;
}

// The audio's RMS over one frame's length centred at `t` seconds.
double Envelope(const std::vector<std::int16_t>& a, double t, double fps) {
  const long from = std::max(0L, std::lround((t - 0.5 / fps) * kRate));
  const long to = std::min(static_cast<long>(a.size()), std::lround((t + 0.5 / fps) * kRate));
  if (to <= from) return 0;
  double sum = 0;
  for (long i = from; i < to; ++i) sum += static_cast<double>(a[i]) * a[i];
  return std::sqrt(sum / static_cast<double>(to - from));
}

double Pearson(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(y.size());
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0;
}

// The lag (ms, −300..300 in 1 ms steps) at which the audio's envelope best matches the mouth's
// opening, frame i at i / fps: positive, the sound comes after the mouth.
int AudioLagMs(const std::vector<double>& mouth, const std::vector<std::int16_t>& audio, double fps) {
  int best_lag = 0;
  double best = -2;
  for (int lag = -300; lag <= 300; ++lag) {
    std::vector<double> envelope(mouth.size());
    for (std::size_t i = 0; i < mouth.size(); ++i) envelope[i] = Envelope(audio, static_cast<double>(i) / fps + lag / 1000.0, fps);
    if (const double r = Pearson(mouth, envelope); r > best) {
      best = r;
      best_lag = lag;
    }
  }
  return best_lag;
}

TEST(SpeechSound, SaysVideoCarriesTheLineInStepWithTheMouth) {
  const fs::path dir = TempFolder("say");
  const fs::path scene = dir / "scene.yaml";
  std::ofstream(scene) << "characters:\n  - asset: builtin:figure\n    keys: [{azimuth: 0, generate: lookat}]\n";
  const CommandResult said = testing::RunArview(
      {"say", "--scene", scene.string(), "Hello! My mom bought a big brown bag. Peter picked a basket of purple plums.",
       "--out", (dir / "say.mp4").string(), "--curves", (dir / "curves.json").string(), "--size", "160x120"});
  ASSERT_EQ(said.exit_code, 0) << said.err;
  const nlohmann::json curves = nlohmann::json::parse(testing::ReadWholeFile((dir / "curves.json").string()));
  const double fps = curves.at("fps").get<double>();
  std::vector<double> mouth;
  for (const auto& f : curves.at("frames")) mouth.push_back(f.at("mouth_open").get<double>());

  const double video_s = StreamDuration(dir / "say.mp4", "video", dir);
  const double audio_s = StreamDuration(dir / "say.mp4", "audio", dir);
  EXPECT_NEAR(video_s, static_cast<double>(mouth.size()) / fps, 0.5 / fps);
  EXPECT_NEAR(audio_s, video_s, 1.0 / fps) << "the audio track lasts as long as the video, within one frame";

  const std::vector<std::int16_t> audio = DecodeAudio(dir / "say.mp4", dir);
  ASSERT_GT(audio.size(), static_cast<std::size_t>(curves.at("samples").get<int>()));
  const int lag = AudioLagMs(mouth, audio, fps);
  std::printf("audio lag behind the mouth: %+d ms (ITU-R BT.1359: -45..+125)\n", lag);
  EXPECT_GE(lag, -45) << "the sound leads the mouth by more than 45 ms";
  EXPECT_LE(lag, 125) << "the sound lags the mouth by more than 125 ms";
  // The measurement sees a shift: the same audio 150 ms later is found 150 ms later (±1 frame).
  std::vector<std::int16_t> later(kRate * 150 / 1000, 0);
  later.insert(later.end(), audio.begin(), audio.end());
  EXPECT_NEAR(AudioLagMs(mouth, later, fps) - lag, 150, 1000.0 / fps);
  fs::remove_all(dir);
}

class SpeechSoundLive : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(tracker::testing::kGraffitiTexture, "Debian package opencv-doc");
    dir_ = TempFolder("live");
    ::setenv("ARVIEW_CACHE_DIR", (dir_ / "cache").c_str(), 1);
    testing::WriteGraffitiMapFolder(dir_ / "map");
    testing::WriteGraffitiViews(dir_ / "views");  // its first 6 frames dark
    // The emulated camera's loop (30 fps): 1.2 s black (lost after 0.5 s: the `lost` line), then
    // 1.8 s of the views (found: the `found` line), so that the character talks every loop. Black,
    // not the views' dark frames: the tracker follows those across a light change (docs/tracker.md).
    std::vector<recordings::FrameEntry> loop;
    for (int i = 0; i < 90; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "frames/%06d.png", 6 + (i - 36) / 3);
      loop.push_back({i / 30.0, i < 36 ? std::string("frames/black.png") : std::string(name)});
    }
    fs::copy(dir_ / "views", dir_ / "talk", fs::copy_options::recursive);
    const cv::Mat view = cv::imread((dir_ / "talk" / "frames" / "000006.png").string());
    ASSERT_FALSE(view.empty());
    cv::imwrite((dir_ / "talk" / "frames" / "black.png").string(), cv::Mat::zeros(view.size(), view.type()));
    recordings::WriteFramesTxt(dir_ / "talk", loop);
    std::ofstream(dir_ / "scene.yaml")
        << "characters:\n  - asset: builtin:figure\n    keys: [{azimuth: 0, generate: lookat}]\n    lines:\n"
           "      - when: start\n        say: Hello there!\n"
           "      - when: lost\n        say: Hey?\n"
           "      - when: found\n        say: There you are!\n";
  }
  void TearDown() override {
    ::unsetenv("ARVIEW_CACHE_DIR");
    if (!HasFailure()) fs::remove_all(dir_);
  }
  CommandResult Run(const std::string& audio_out, double seconds, const std::vector<std::string>& more = {},
                    std::map<std::string, std::string> env = {}) {
    std::vector<std::string> args = {"run", "--device", testing::kEmulatedCamera, "--map", (dir_ / "map").string(),
                                     "--scene", (dir_ / "scene.yaml").string(), "--out", "null",
                                     "--audio-out", audio_out, "--stats", (dir_ / "stats.json").string()};
    args.insert(args.end(), more.begin(), more.end());
    env["ARVIEW_FAKE_CAMERA_RECORDING"] = (dir_ / "talk").string();
    return testing::RunWithEmulatedCamera(args, env, dir_, {0, 0}, seconds * testing::kSanitizerSlowdown);
  }
  fs::path dir_;
};

double SoakSeconds() {
  const char* text = std::getenv("ARVIEW_SPEECH_SOAK_SECONDS");
  return text ? std::atof(text) : 10.0;
}

TEST_F(SpeechSoundLive, EachLinesFirstSampleIsHeardWithItsFrameAndNothingUnderruns) {
  const testing::EmulatedSound sound(dir_ / "sound");
  const double seconds = SoakSeconds();
  const CommandResult r = Run("arview_speaker", seconds);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("no sound"), std::string::npos) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(testing::ReadWholeFile((dir_ / "stats.json").string()));
  const nlohmann::json& s = stats.at("sound");
  ASSERT_TRUE(s.at("playing").get<bool>());
  EXPECT_EQ(s.at("underruns").get<int>(), 0);
  EXPECT_EQ(s.at("underruns_in_lines").get<int>(), 0);
  EXPECT_EQ(s.at("clips_late").get<int>(), 0);
  EXPECT_FALSE(s.at("player_scheduling").get<std::string>().empty());
  std::printf("%s", r.out.c_str());
  std::vector<double> latencies;
  for (const auto& f : stats.at("frames")) latencies.push_back(f.at("latency_ms").get<double>());
  std::nth_element(latencies.begin(), latencies.begin() + latencies.size() / 2, latencies.end());
  const double median_latency_ms = latencies.at(latencies.size() / 2);
  int heard = 0;
  for (const auto& line : s.at("lines")) {
    const double start = line.at("start_s").get<double>(), heard_s = line.at("heard_s").get<double>();
    // The session ended before it played, or before the frame its mouth starts on was shown
    // (the player had its first samples already: a line is handed over ahead of its frame).
    if (heard_s < 0 || line.at("shown_s").get<double>() < 0) continue;
    // The frame on which the mouth starts to move: the first shown whose animation time reaches the line's start.
    const nlohmann::json* frame = nullptr;
    for (const auto& f : stats.at("frames"))
      if (f.contains("animation_s") && f.at("animation_s").get<double>() >= start - 1e-6) {
        frame = &f;
        break;
      }
    ASSERT_NE(frame, nullptr) << line.dump();
    const double latency_ms = frame->at("latency_ms").get<double>();
    // When the frames at the line's start were dropped (a loaded machine, a sanitizer build), the
    // first one shown is this much later in the animation, and was shown that much after the
    // line's start would have been: the sound is due that much before it.
    const double dropped_s = frame->at("animation_s").get<double>() - start;
    const double shown_s = frame->at("captured_s").get<double>() + latency_ms / 1000 - dropped_s;
    std::printf("%s at %.3f s: first sample heard %+.1f ms from frame %lld's display less %.1f ms dropped (its latency "
                "%.1f ms, median %.1f)\n",
                line.at("origin").get<std::string>().c_str(), start, 1000 * (heard_s - shown_s),
                frame->at("index").get<long long>(), 1000 * dropped_s, latency_ms, median_latency_ms);
    // Within 40 ms of the frame's display; a frame shown later or earlier than the frames usually
    // are (the loaded machine's stalls: the video's timing, not the sound's) is allowed the difference.
    EXPECT_NEAR(heard_s, shown_s, 0.040 + std::abs(latency_ms - median_latency_ms) / 1000) << line.dump();
    ++heard;
  }
  EXPECT_GE(heard, 1) << "the start line at least, in " << seconds << " s";
  std::printf("%d lines heard in %.0f s\n", heard, seconds);
  // What the speaker received is the lines, not silence alone.
  const std::vector<std::int16_t> played = sound.Played();
  std::int64_t loud = 0;
  for (std::int16_t v : played) loud += std::abs(v) > 1000;
  EXPECT_GT(loud, kRate / 10) << played.size() << " samples played";
}

TEST_F(SpeechSoundLive, NoSoundDeviceIsOneNoteAndTheSessionGoesOnSilent) {
  const testing::EmulatedSound sound(dir_ / "sound");
  const CommandResult missing = Run(testing::EmulatedSound::kMissing, 4);
  EXPECT_EQ(missing.exit_code, 0) << missing.err;
  std::size_t notes = 0;
  for (std::size_t at = missing.err.find("no sound: "); at != std::string::npos; at = missing.err.find("no sound: ", at + 1)) ++notes;
  EXPECT_EQ(notes, 1u) << missing.err;
  EXPECT_NE(missing.err.find("sound output '" + std::string(testing::EmulatedSound::kMissing) + "'"), std::string::npos);
  EXPECT_FALSE(nlohmann::json::parse(testing::ReadWholeFile((dir_ / "stats.json").string())).contains("sound"))
      << "no player, no video: nothing about sound";

  const CommandResult off = Run("none", 3);
  EXPECT_EQ(off.exit_code, 0) << off.err;
  EXPECT_EQ(off.err.find("no sound"), std::string::npos) << off.err;
}

// A speaker pulled out mid-session (tests/support/pcm_unplug.cpp: ALSA answers "no such device"
// 2 s after the player's first write, which comes before the first frame): one note naming the
// device, the session goes on silent to its end, and the stats say why.
TEST_F(SpeechSoundLive, ASpeakerUnpluggedMidSessionIsOneNoteAndTheSessionGoesOnSilent) {
  const testing::EmulatedSound sound(dir_ / "sound");
  const CommandResult r = Run("arview_speaker", 9, {},
                              {{"LD_PRELOAD", std::string(ARVIEW_FAKE_V4L2_LIBRARY) + ":" + ARVIEW_PCM_UNPLUG_LIBRARY},
                               {"ARVIEW_PCM_UNPLUG", "playback"},
                               {"ARVIEW_PCM_UNPLUG_AFTER_S", "2"}});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string note = "note: sound output 'arview_speaker': the device disappeared";
  std::size_t notes = 0;
  for (std::size_t at = r.err.find(note); at != std::string::npos; at = r.err.find(note, at + 1)) ++notes;
  EXPECT_EQ(notes, 1u) << r.err;
  EXPECT_NE(r.out.find("the device disappeared"), std::string::npos) << "the summary's sound line says why:\n" << r.out;
  const nlohmann::json stats = nlohmann::json::parse(testing::ReadWholeFile((dir_ / "stats.json").string()));
  const nlohmann::json& s = stats.at("sound");
  EXPECT_NE(s.at("error").get<std::string>().find("the device disappeared (ALSA: No such device)"), std::string::npos) << s.dump();
  // The session went on: frames were shown for at least 2 s after the unplug (which came at most
  // 2 s after the first frame).
  ASSERT_FALSE(stats.at("frames").empty());
  EXPECT_GT(stats.at("frames").back().at("captured_s").get<double>() - stats.at("frames").front().at("captured_s").get<double>(), 4.0);
}

TEST_F(SpeechSoundLive, ReplayWritesTheLinesIntoTheVideosAudioTrack) {
  const fs::path video = dir_ / "replay.mp4";
  const CommandResult r = testing::RunArview({"replay", (dir_ / "views").string(), "--map", (dir_ / "map").string(),
                                              "--scene", (dir_ / "scene.yaml").string(), "--out", video.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("in the video's audio track"), std::string::npos) << r.out;
  const double video_s = StreamDuration(video, "video", dir_), audio_s = StreamDuration(video, "audio", dir_);
  EXPECT_NEAR(video_s, 2.4, 0.05);
  EXPECT_NEAR(audio_s, video_s, 0.1) << "one frame at 10 fps";
  const std::vector<std::int16_t> audio = DecodeAudio(video, dir_);
  // Silent before the start line (the first tracked frame, the seventh: 0.6 s), speech after it.
  double before = 0, after = 0;
  for (std::size_t i = 0; i < audio.size(); ++i) (i < kRate * 55 / 100 ? before : after) += std::abs(audio[i]);
  EXPECT_LT(before / (kRate * 0.55), 5.0);
  EXPECT_GT(after / std::max<double>(1, static_cast<double>(audio.size()) - kRate * 0.55), 100.0);
}

}  // namespace
}  // namespace arview
