#pragma once
// A rendered room with exact ground truth (`arview synth room`): the inside of a 7 x 5 x 2.8 m
// room whose walls, floor, ceiling and three boxes carry real photos from Debian's opencv-doc
// package, filmed at 640x480 and 30 fps along a smooth hand-held-like path (a walk round the
// room looking at the walls, panning, a little shake and one fast turn).
//
// World frame: metres, z up, floor at z = 0, room centred on the origin (x in [−3.5, 3.5],
// y in [−2.5, 2.5], z in [0, 2.8]).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"
#include "render/offscreen.h"
#include "render/textured_scene.h"
#include "synth/orbit_walk.h"
#include "synth/room_lights.h"
#include "synth/room_walkers.h"

namespace arview::synth {

inline const char* kOpenCvDocData = "/usr/share/doc/opencv-doc/examples/data";

// One textured rectangle of the room, kept for tests and tools: its corners in the world
// (top-left, top-right, bottom-right, bottom-left of the upright texture) and its image.
struct RoomPanel {
  std::string image_name;
  Eigen::Vector3d corners[4];
  int texture = 0;
};

struct RoomScene {
  std::vector<cv::Mat> textures;       // textures[0] is plain white (wall paint)
  std::vector<render::TriangleBatch> batches;  // everything drawn
  std::vector<RoomPanel> panels;       // the photo rectangles only
};

// How the room is lit; the light is baked into the surfaces' shades (nothing is lit at render
// time), so a frame's brightness depends only on what it sees.
//   kEven:   evenly from all round, a light floor (the tracking tests' room).
//   kWindow: daylight through a window in the +y wall (x in [−1.575, −0.175], z in [0.9, 2.5]), the
//            pane clipped white, a dark floor under light walls: the light has a direction that
//            a camera in the room sees, so `arview place` finds a dominant light above the floor
//            and the character casts a shadow (`arview demo`). One wall photo (graf1) gives way
//            to the window.
enum class SynthLighting { kEven, kWindow };

// A printed chessboard lying flat on the floor (`arview synth room --board 9x6 --square 0.1`),
// black and white squares with a white margin one square wide, for maps made metric and upright
// from a board (`arview map --board`, docs/mapping.md "Metric scale and up"). Its corners are
// exact: the board is part of the room's geometry.
struct FloorBoard {
  cv::Size inner_corners{0, 0};        // inner corners per row and per column; 0x0: no board
  double square = 0.1;                 // metres
  Eigen::Vector2d centre{0, 0};        // the board's centre on the floor
  double yaw = 0;                      // radians: its rows run along (cos yaw, sin yaw)

  bool empty() const { return inner_corners.width <= 0 || inner_corners.height <= 0; }
  // The inner corners in the world, row after row (x along a row): the order of OpenCV's
  // findChessboardCorners up to the board's symmetries (which corner it starts from).
  std::vector<Eigen::Vector3d> Corners() const;
};

// Loads the photos from `data_dir`; throws RenderError naming a missing or unreadable file.
RoomScene MakeRoomScene(const std::filesystem::path& data_dir = kOpenCvDocData, SynthLighting light = SynthLighting::kEven,
                        const FloorBoard& board = {});

// The window of SynthLighting::kWindow: its outer frame on the +y wall (world metres), the bars'
// width and the transom's height (a mullion halves it at its middle).
struct WindowGeometry {
  double wall_y, x_min, x_max, z_min, z_max, bar, transom_z;
};
WindowGeometry RoomWindow();

// The distance along a ray from a point inside the room (`direction` unit) to the first of its
// walls, floor, ceiling and boxes (the photos lie on them); infinity when it starts outside.
double RoomRayDepth(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction);

// The synthetic camera: 640x480, fx = fy = 525, principal point slightly off centre, no distortion.
// Other sizes keep the horizontal field of view (f and the principal point offset scale with
// width / 640, pixel centres in OpenCV's convention); a wider aspect crops top and bottom.
calib::Camera RoomCamera(int width = 640, int height = 480);

// A distorted camera's frames from a pinhole rendering: the pinhole camera to render with (the
// same focal length, big enough for every ray of the lens, at most 3 times the frame's side; a
// RenderError beyond), and the map that resamples its picture into the lens's.
class DistortedRoom {
 public:
  explicit DistortedRoom(const calib::Camera& lens);
  const calib::Camera& pinhole() const { return pinhole_; }
  // The pinhole picture (the pinhole camera's size) as the lens sees it (the lens's size).
  cv::Mat Distort(const cv::Mat& pinhole_picture) const;

 private:
  calib::Camera pinhole_;
  cv::Mat map_x_, map_y_;
};

// The hand-held path: camera pose (world → camera) at time t (seconds) for a sequence of
// `duration` seconds; deterministic for a seed. The fast turn (90° in 0.6 s) starts at 55% of
// the duration.
class RoomPath {
 public:
  RoomPath(double duration, uint64_t seed);
  calib::Pose At(double t) const;

 private:
  double duration_;
  double angle0_, direction_, pan_phase_, pitch_phase_, roll_phase_, bob_phase_, turn_sign_;
  double shake_phase_[6];
};

// The camera's walk: RoomPath (round the room's centre, looking at the walls), or OrbitWalk
// (two laps round a spot where a character stands, for `arview demo`).
enum class RoomWalk { kRoom, kOrbit };

struct SynthRoomOptions {
  std::filesystem::path out;
  RoomWalk walk = RoomWalk::kRoom;
  SynthLighting light = SynthLighting::kEven;
  OrbitWalkOptions orbit;        // for RoomWalk::kOrbit
  FloorBoard board;              // none by default
  int frames = 300;
  uint64_t seed = 1;
  double fps = 30.0;
  int motion_blur_samples = 0;   // 0 or 1: none; N > 1: average N renders over the exposure
  double exposure_s = 1.0 / 60;  // shutter time spanned by motion blur
  double noise_sigma = 0.0;      // additive Gaussian sensor noise, grey levels (8-bit)
  int width = 640, height = 480; // frame size (e.g. 1280x720, 1920x1080)
  // Another lens than RoomCamera's: its focal length times this (0.7: a wider lens), and OpenCV's
  // distortion k1 k2 p1 p2 k3 (all zero: none). A distorted frame is rendered as a pinhole picture
  // wide enough for every ray of the lens, then resampled through the distortion (DistortedRoom).
  double focal_scale = 1.0;
  std::array<double, 5> distortion{};
  int jpeg_quality = 0;          // 0: frames as PNG; 1..100: JPEG at this quality
  // Exposure/gain change over time: brightness multiplied by 1 + gain_drift·sin(2πt / 7 s)
  // (auto-exposure hunting); 0: off.
  double gain_drift = 0.0;
  // Rolling shutter: rows are read out over this time, top to bottom (each of 16 bands is
  // rendered at its own time); 0: global shutter.
  double rolling_shutter_s = 0.0;
  int samples = 4;               // MSAA samples
  // Only these frames of the `frames`-long walk are rendered and listed (recordings::
  // ParseFrameSpec syntax, e.g. "0-649:8,650-949"); empty: every frame. The walk, the noise
  // and every rendered frame are exactly those of the full recording: a subset makes sizes
  // whose frames take seconds each affordable (a sparse first lap to map, a dense stretch to track).
  std::string frames_subset;
  // A tripod (`--still S --still-at T`): at the walk's time `still_at_s` the camera stops for
  // `still_s` seconds, then walks on; the recording is that much longer than the `frames`-long
  // walk, and its still frames differ only by the sensor's noise and compression (a still
  // camera's jitter is measured there: `arview eval`). 0: no still segment.
  double still_s = 0.0;
  double still_at_s = 0.0;
  // People walking through (room_walkers.h): their circles go round `walkers.spot`, which
  // SynthesizeRoom sets to the orbit's subject on the orbit walk (the room's centre otherwise).
  WalkersOptions walkers;
  // The lamp, the sun through the window, the camera's auto-exposure (room_lights.h); times in the
  // recording's seconds (SynthesizeRoom sets `duration_s`).
  LightChanges lights;
  bool overwrite = false;        // replace an existing recording in `out`
  std::filesystem::path data_dir = kOpenCvDocData;
  render::OffscreenOptions gl;
};

// The camera of a recording of `options` (RoomCamera at its size, its focal length scaled by
// focal_scale, its distortion).
calib::Camera SynthCamera(const SynthRoomOptions& options);

// The recording's frame count: the walk's `frames` and the still segment's.
int RecordingFrames(const SynthRoomOptions& options);
// The walk's time at the recording's time t: t before the still segment, its start during it, t
// less its length after.
double WalkTime(const SynthRoomOptions& options, double t);

struct SynthRoomReport {
  std::string gl_description;
  int frames = 0;
};

// Renders and writes the recording: frames/NNNNNN.png (or .jpg), frames.txt, camera.yaml and
// groundtruth.txt (TUM, camera-to-world, pose at the middle of each exposure; with a rolling
// shutter, of the middle row's exposure); with walkers, walkers.txt: each frame's time and the
// share of its pixels the walkers cover.
// `progress(done, total)` is called after every frame when given.
SynthRoomReport SynthesizeRoom(const SynthRoomOptions& options,
                               const std::function<void(int, int)>& progress = nullptr);

// Renders one frame of the room (no noise), for tests and previews.
class RoomRenderer {
 public:
  RoomRenderer(render::OffscreenContext& context, const RoomScene& scene, const calib::Camera& camera, int samples);
  ~RoomRenderer();
  // People walking through, drawn by Render(pose, t) from now on.
  void SetWalkers(const WalkersOptions& walkers);
  cv::Mat Render(const calib::Pose& pose);            // the room alone
  cv::Mat Render(const calib::Pose& pose, double t);  // with the walkers where they are at time t

 private:
  render::OffscreenContext* context_;
  calib::Camera camera_;
  render::TexturedScene scene_;
  render::RenderTarget target_;
  std::unique_ptr<WalkersRenderer> walkers_;
};

}  // namespace arview::synth
