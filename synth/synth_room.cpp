// `arview synth room`'s recording (SynthesizeRoom, synth_room.h), apart from the room it films
// (room_scene.cpp): the options checked, each frame rendered over its exposure (motion blur, a
// rolling shutter) with the walkers and the light changes, gain drift and sensor noise, and the
// recording folder written (frames, frames.txt, camera.yaml, groundtruth.txt, walkers.txt).

#include "synth/synth_room.h"

#include "base/atomic_file.h"
#include "base/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "synth/recording_folder.h"
#include "synth/room_size.h"

namespace arview::synth {
namespace {

namespace fs = std::filesystem;

void ValidateOptions(const SynthRoomOptions& o) {
  auto fail = [](const std::string& what) { throw render::RenderError("synth room: " + what); };
  if (o.out.empty()) fail("an output folder is required");
  if (o.frames < 1 || o.frames > 1000000) fail("--frames must be in 1..1000000, got " + std::to_string(o.frames));
  if (!(o.fps > 0 && o.fps <= 1000)) fail("frame rate must be in (0, 1000]");
  if (o.motion_blur_samples < 0 || o.motion_blur_samples > 64) fail("--motion-blur must be in 0..64 samples");
  if (!(o.exposure_s >= 0 && o.exposure_s <= 1.0 / o.fps)) fail("--exposure must be in [0, 1/fps] seconds");
  if (!(o.noise_sigma >= 0 && o.noise_sigma <= 64)) fail("--noise must be in [0, 64] grey levels");
  if (o.width < 64 || o.height < 48 || o.width > 7680 || o.height > 4320)
    fail("--size must be between 64x48 and 7680x4320, got " + std::to_string(o.width) + "x" + std::to_string(o.height));
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100) fail("--jpeg must be in 0..100 (0: PNG)");
  if (!(o.gain_drift >= 0 && o.gain_drift < 1)) fail("--gain-drift must be in [0, 1)");
  if (!(o.rolling_shutter_s >= 0 && o.rolling_shutter_s <= 1.0 / o.fps))
    fail("--rolling-shutter must be in [0, 1/fps] seconds");
  if (!(o.still_s >= 0 && o.still_s <= 3600)) fail("--still must be in [0, 3600] seconds");
  if (!(o.still_at_s >= 0 && o.still_at_s <= o.frames / o.fps)) {
    fail("--still-at must be within the walk, [0, " + std::to_string(o.frames / o.fps) + "] seconds");
  }
  const double duration = RecordingFrames(o) / o.fps;
  if (o.walkers.count < 0 || o.walkers.count > kMaxWalkers) {
    fail("--walkers must be in 0.." + std::to_string(kMaxWalkers) + ", got " + std::to_string(o.walkers.count));
  }
  if (!(o.walkers.from_s >= 0 && o.walkers.from_s <= duration)) {
    fail("--walkers-from must be within the recording, [0, " + std::to_string(duration) + "] seconds");
  }
  const LightChanges& l = o.lights;
  if (l.lamp_off_s > duration) fail("--lamp-off must be within the recording, [0, " + std::to_string(duration) + "] seconds");
  if (l.lamp_on_s >= 0 && !(l.lamp_off_s >= 0 && l.lamp_on_s > l.lamp_off_s)) {
    fail("--lamp-on needs an earlier --lamp-off (the lamp is on until then)");
  }
  if (l.sun && o.light != SynthLighting::kWindow) fail("--sun needs --light window (the sun comes through its window)");
  if (!(o.focal_scale >= 0.25 && o.focal_scale <= 4)) fail("--focal-scale must be in [0.25, 4]");
  for (const double k : o.distortion) {
    if (!(std::abs(k) <= 10)) fail("--distortion's terms must be finite and within [-10, 10]");
  }
  const bool distorted = std::any_of(o.distortion.begin(), o.distortion.end(), [](double k) { return k != 0; });
  if (distorted && o.walkers.count > 0) fail("--distortion with --walkers is not rendered (the walkers' mask is the pinhole's)");
  if (distorted && o.rolling_shutter_s > 0) fail("--distortion with --rolling-shutter is not rendered");
  if (!o.board.empty()) {
    if (!(o.board.square > 0 && o.board.square <= 1)) fail("--square must be in (0, 1] metres");
    const double reach = 0.5 * o.board.square * std::hypot(o.board.inner_corners.width + 3, o.board.inner_corners.height + 3);
    if (std::abs(o.board.centre.x()) + reach > kHalfX || std::abs(o.board.centre.y()) + reach > kHalfY)
      fail("the board does not fit on the floor there (the room is 7 x 5 m, centred on 0,0)");
  }
}

// The recording's frames to render, in order: every one, or the --subset's.
std::vector<int> FramesToRender(const SynthRoomOptions& o) {
  const int frames = RecordingFrames(o);
  if (o.frames_subset.empty()) {
    std::vector<int> every(frames);
    for (int i = 0; i < frames; ++i) every[i] = i;
    return every;
  }
  try {
    return recordings::ParseFrameSpec(o.frames_subset, frames);
  } catch (const Error& e) {
    throw render::RenderError(std::string("synth room: --subset: ") + e.what());
  }
}

void PrepareFolder(const SynthRoomOptions& o) {
  PrepareRecordingFolder(o.out, o.overwrite, {"frames.txt", "groundtruth.txt", "camera.yaml", "walkers.txt"});
}

using PoseAt = std::function<calib::Pose(double)>;

cv::Mat RenderGlobalExposure(RoomRenderer& renderer, const PoseAt& path, double t, const SynthRoomOptions& o) {
  if (o.motion_blur_samples <= 1 || o.exposure_s == 0) return renderer.Render(path(t), t);
  cv::Mat sum;
  for (int k = 0; k < o.motion_blur_samples; ++k) {
    const double offset = o.exposure_s * (static_cast<double>(k) / (o.motion_blur_samples - 1) - 0.5);
    cv::Mat frame;
    renderer.Render(path(t + offset), t + offset).convertTo(frame, CV_32FC3);
    if (sum.empty()) sum = frame;
    else sum += frame;
  }
  cv::Mat out;
  sum.convertTo(out, CV_8UC3, 1.0 / o.motion_blur_samples);
  return out;
}

// A rolling shutter reads row y at t + (y / H − 1/2)·readout: 16 horizontal bands, each rendered
// (with its motion blur) at its middle row's time.
cv::Mat RenderExposure(RoomRenderer& renderer, const PoseAt& path, double t, const SynthRoomOptions& o) {
  if (o.rolling_shutter_s <= 0) return RenderGlobalExposure(renderer, path, t, o);
  constexpr int kBands = 16;
  cv::Mat out(o.height, o.width, CV_8UC3);
  for (int b = 0; b < kBands; ++b) {
    const int y0 = o.height * b / kBands, y1 = o.height * (b + 1) / kBands;
    const double row_time = t + ((y0 + y1) / 2.0 / o.height - 0.5) * o.rolling_shutter_s;
    RenderGlobalExposure(renderer, path, row_time, o).rowRange(y0, y1).copyTo(out.rowRange(y0, y1));
  }
  return out;
}

void ApplyGain(cv::Mat& image, double drift, double t) {
  if (drift <= 0) return;
  image.convertTo(image, CV_8UC3, 1.0 + drift * std::sin(2 * M_PI * t / 7.0));  // saturating
}

void AddNoise(cv::Mat& image, double sigma, uint64_t seed, int frame) {
  if (sigma <= 0) return;
  cv::RNG rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<uint64_t>(frame) + 1);
  cv::Mat noise(image.size(), CV_32FC3), noisy;
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  image.convertTo(noisy, CV_32FC3);
  noisy += noise;
  noisy.convertTo(image, CV_8UC3);  // saturating
}

// The pixels the walkers cover at time t (8-bit, 255 there): where the frame with them differs
// from the room alone; `with_walkers` is that frame when the exposure was a single render.
cv::Mat WalkerPixels(RoomRenderer& renderer, const calib::Pose& pose, double t, const SynthRoomOptions& o,
                     const cv::Mat& with_walkers) {
  const bool single_render = (o.motion_blur_samples <= 1 || o.exposure_s == 0) && o.rolling_shutter_s <= 0;
  const cv::Mat with = single_render ? with_walkers : renderer.Render(pose, t);
  cv::Mat difference, mask;
  cv::absdiff(with, renderer.Render(pose), difference);
  cv::cvtColor(difference, difference, cv::COLOR_BGR2GRAY);
  cv::threshold(difference, mask, 0, 255, cv::THRESH_BINARY);
  return mask;
}

void WriteWalkersTxt(const fs::path& file, const std::vector<std::pair<double, double>>& covered) {
  std::string text = "# arview synth room: the share of each frame's pixels that people walking through cover\n"
                     "# timestamp share\n";
  for (const auto& [t, share] : covered) {
    char line[64];
    std::snprintf(line, sizeof line, "%.9f %.4f\n", t, share);
    text += line;
  }
  WriteFileAtomically(file, text);
}

// The people and light changes in the ground truth's header.
std::string ConditionsText(const SynthRoomOptions& o) {
  std::string text;
  char part[160];
  if (o.walkers.count > 0) {
    std::snprintf(part, sizeof part, ", %d walker%s from %.4g s round (%.3f, %.3f)", o.walkers.count,
                  o.walkers.count > 1 ? "s" : "", o.walkers.from_s, o.walkers.spot.x(), o.walkers.spot.y());
    text += part;
  }
  if (o.lights.lamp_off_s >= 0) {
    std::snprintf(part, sizeof part, ", lamp off at %.4g s", o.lights.lamp_off_s);
    text += part;
  }
  if (o.lights.lamp_on_s >= 0) {
    std::snprintf(part, sizeof part, ", on at %.4g s", o.lights.lamp_on_s);
    text += part;
  }
  if (o.lights.sun) text += ", sun through the window moving";
  if (o.lights.auto_exposure) text += ", auto-exposure";
  return text;
}

// The board in the ground truth's header: whoever reads the recording learns its size and place.
std::string BoardText(const FloorBoard& board) {
  if (board.empty()) return "";
  char text[160];
  std::snprintf(text, sizeof text, ", chessboard %dx%d of %.4g m squares on the floor at (%.3f, %.3f), yaw %.1f deg",
                board.inner_corners.width, board.inner_corners.height, board.square, board.centre.x(), board.centre.y(),
                board.yaw * 180 / M_PI);
  return text;
}

// The still segment in the ground truth's header.
std::string StillText(const SynthRoomOptions& o) {
  if (o.still_s <= 0) return "";
  char text[96];
  std::snprintf(text, sizeof text, ", still for %.4g s from %.4g s", o.still_s, o.still_at_s);
  return text;
}

}  // namespace

int RecordingFrames(const SynthRoomOptions& o) { return o.frames + static_cast<int>(std::lround(o.still_s * o.fps)); }

double WalkTime(const SynthRoomOptions& o, double t) {
  if (t < o.still_at_s) return t;
  return std::max(o.still_at_s, t - o.still_s);
}

SynthRoomReport SynthesizeRoom(const SynthRoomOptions& options, const std::function<void(int, int)>& progress) {
  ValidateOptions(options);
  SynthRoomOptions o = options;
  o.walkers.spot = o.walk == RoomWalk::kOrbit ? o.orbit.subject : Eigen::Vector2d::Zero();
  o.lights.duration_s = RecordingFrames(o) / o.fps;
  const std::vector<int> indices = FramesToRender(o);
  const RoomScene scene = MakeRoomScene(o.data_dir, o.light, o.board);
  const calib::Camera camera = SynthCamera(o);
  const bool distorted = camera.HasDistortion();
  std::optional<DistortedRoom> lens;
  if (distorted) lens.emplace(camera);
  std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create(o.gl);
  PrepareFolder(o);
  // What is drawn and lit: the camera's own picture, or the pinhole one a distorted lens resamples.
  const calib::Camera& drawn = distorted ? lens->pinhole() : camera;
  RoomRenderer renderer(*context, scene, drawn, o.samples);
  renderer.SetWalkers(o.walkers);
  const RoomPath room_path(o.frames / o.fps, o.seed);
  const OrbitWalk orbit_walk(o.frames / o.fps, o.seed, o.orbit);
  const PoseAt path = [&](double t) {
    const double w = WalkTime(o, t);
    return o.walk == RoomWalk::kOrbit ? orbit_walk.At(w) : room_path.At(w);
  };

  std::vector<recordings::FrameEntry> entries;
  recordings::Trajectory groundtruth;
  std::vector<std::pair<double, double>> covered;  // by the walkers: time, share of the frame
  // PNG encoding of frame i overlaps the rendering of frame i + 1.
  std::future<bool> pending_write;
  std::string pending_name;
  auto finish_write = [&] {
    if (pending_write.valid() && !pending_write.get()) {
      throw render::RenderError((o.out / pending_name).string() + ": cannot write the frame");
    }
  };
  for (size_t n = 0; n < indices.size(); ++n) {
    const int i = indices[n];
    const double t = i / o.fps;
    cv::Mat image = RenderExposure(renderer, path, t, o);
    cv::Mat walkers;
    if (o.walkers.count > 0) {
      walkers = WalkerPixels(renderer, path(t), t, o, image);
      covered.emplace_back(t, static_cast<double>(cv::countNonZero(walkers)) / static_cast<double>(walkers.total()));
    }
    ApplyLightChanges(image, o.lights, drawn, path(t), o.fps, i, walkers);
    if (distorted) image = lens->Distort(image);
    ApplyGain(image, o.gain_drift, t);
    AddNoise(image, o.noise_sigma, o.seed, i);
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.%s", i, o.jpeg_quality > 0 ? "jpg" : "png");
    finish_write();
    pending_name = name;
    const std::vector<int> params = o.jpeg_quality > 0 ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality}
                                                       : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 1};
    pending_write = std::async(std::launch::async, [file = (o.out / name).string(), image, params] {
      try {
        WriteImageAtomically(file, image, params);
        return true;
      } catch (const Error&) {
        return false;
      }
    });
    entries.push_back({t, name});
    groundtruth.push_back({t, path(t)});
    if (progress) progress(static_cast<int>(n) + 1, static_cast<int>(indices.size()));
  }
  finish_write();
  calib::SaveCamera(camera, o.out / "camera.yaml");
  recordings::WriteFramesTxt(o.out, entries);
  if (o.walkers.count > 0) WriteWalkersTxt(o.out / "walkers.txt", covered);
  recordings::WriteTum(groundtruth, o.out / "groundtruth.txt",
                       "arview synth room, seed " + std::to_string(o.seed) + (o.light == SynthLighting::kWindow ? ", window light" : "") +
                           BoardText(o.board) + StillText(o) + ConditionsText(o) + ", world: metres, z up, floor z = 0");
  return {context->Description(), static_cast<int>(indices.size())};
}

}  // namespace arview::synth
