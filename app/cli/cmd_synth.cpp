// arview synth room --out <recording> [--frames N] [--seed S] [--motion-blur N] [--noise sigma] ...

#include <chrono>
#include <iostream>
#include <map>

#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"
#include "app/cli/numeric_flags.h"
#include "synth/synth_room.h"
#include "synth/synth_venue.h"

namespace arview::app {

namespace {

struct SynthArgs {
  synth::SynthRoomOptions options;
  std::string out;
  std::string data_dir = synth::kOpenCvDocData;
  GlFlags gl{2};
  std::string size = "640x480";
  std::string board;                     // inner corners, e.g. 9x6; empty: no board
  std::vector<double> board_at;          // x, y on the floor; empty: the walk's centre
  double board_yaw_deg = 0;
  std::vector<double> distortion;        // k1 k2 p1 p2 k3; empty: none
  bool quiet = false;
};

// The board lies where the walk looks: round the demo's character spot on an orbit walk, in the
// middle of the room on the room walk.
void SetUpBoard(SynthArgs& args) {
  synth::SynthRoomOptions& o = args.options;
  if (args.board.empty()) return;
  o.board.inner_corners = *ParseFrameSize(args.board);  // checked by --board's validator
  o.board.yaw = args.board_yaw_deg * M_PI / 180;
  if (args.board_at.size() == 2) {
    o.board.centre = {args.board_at[0], args.board_at[1]};
  } else {
    // Beside the spot rather than under the character, where the first lap sees the whole board.
    o.board.centre = o.walk == synth::RoomWalk::kOrbit ? Eigen::Vector2d(o.orbit.subject + Eigen::Vector2d(1.1, 0))
                                                       : Eigen::Vector2d::Zero();
  }
}

void RunSynthRoom(SynthArgs& args) {
  synth::SynthRoomOptions& o = args.options;
  o.out = args.out;
  o.data_dir = args.data_dir;
  const cv::Size size = *ParseFrameSize(args.size);  // checked by --size's validator
  o.width = size.width;
  o.height = size.height;
  SetUpBoard(args);
  for (size_t i = 0; i < args.distortion.size(); ++i) o.distortion[i] = args.distortion[i];
  const auto start = std::chrono::steady_clock::now();
  o.gl = ToOffscreenOptions(args.gl);
  const synth::SynthRoomReport report = synth::SynthesizeRoom(o, [&](int done, int total) {
    if (!args.quiet && (done % 30 == 0 || done == total)) std::cerr << "\rframe " << done << "/" << total << std::flush;
  });
  if (!args.quiet) std::cerr << "\n";
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "wrote " << report.frames << " frames (" << o.width << "x" << o.height << ", " << o.fps << " fps, seed " << o.seed
            << ") with ground truth to " << args.out << " in " << seconds << " s [" << report.gl_description << "]\n";
}

struct SynthVenueArgs {
  synth::SynthVenueOptions options;
  std::string out;
  GlFlags gl{2};
  std::string size = "640x480";
  bool quiet = false;
};

void RunSynthVenue(SynthVenueArgs& args) {
  synth::SynthVenueOptions& o = args.options;
  o.out = args.out;
  const cv::Size size = *ParseFrameSize(args.size);  // checked by --size's validator
  o.width = size.width;
  o.height = size.height;
  o.gl = ToOffscreenOptions(args.gl);
  const auto start = std::chrono::steady_clock::now();
  const int frames = synth::SynthesizeVenue(o, [&](int done, int total) {
    if (!args.quiet && (done % 30 == 0 || done == total)) std::cerr << "\rframe " << done << "/" << total << std::flush;
  });
  if (!args.quiet) std::cerr << "\n";
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "wrote " << frames << " frames of a walk through " << o.layout.rooms << " rooms (" << o.width << "x" << o.height
            << ") with ground truth and each frame's room (rooms.txt) to " << args.out << " in " << seconds << " s\n";
}

void AddSynthVenueCommand(CLI::App* synth) {
  auto* venue = synth->add_subcommand(
      "venue", "Rooms in a row joined by doors, each textured apart, filmed on a walk that turns round each room "
               "and goes through the doors (640x480, 30 fps); rooms.txt names each frame's room");
  auto args = std::make_shared<SynthVenueArgs>();
  synth::SynthVenueOptions& o = args->options;
  venue->add_option("--out", args->out, "Recording folder to create")->required();
  venue->add_option("--rooms", o.layout.rooms, "Rooms, each 5 x 4 x 2.6 m")
      ->default_val(o.layout.rooms)
      ->check(CLI::Range(2, synth::kMaxVenueRooms));
  venue->add_option("--frames", o.frames, "Frames of the whole walk (30 per second)")
      ->default_val(o.frames)
      ->check(CLI::Range(2, 1000000));
  venue->add_option("--seed", o.seed, "Seed of the rooms' textures")->default_val(o.seed);
  venue->add_option("--size", args->size, "Frame size WxH (field of view kept)")
      ->default_val(args->size)
      ->check(FrameSizeCheck({64, 48}, {7680, 4320}));
  venue->add_option("--subset", o.frames_subset,
                    "Render only these frames of the walk, e.g. 0-239:3 (one room's frames as a recording of its "
                    "own, from rooms.txt); each exactly as in the whole recording");
  AddGlFlags(venue, args->gl);
  venue->add_flag("--force", o.overwrite, "Replace a recording already in --out");
  venue->add_flag("--quiet", args->quiet, "No progress on stderr");
  venue->callback([args] { RunSynthVenue(*args); });
}

}  // namespace

void AddSynthCommand(CLI::App& app) {
  auto* synth = app.add_subcommand("synth", "Render synthetic recordings with exact ground truth ('synth room', 'synth venue')");
  synth->require_subcommand(1);
  auto* room = synth->add_subcommand(
      "room", "A room textured with opencv-doc photos, filmed along a hand-held-like path (640x480, 30 fps)");
  auto args = std::make_shared<SynthArgs>();
  synth::SynthRoomOptions& o = args->options;
  room->add_option("--out", args->out, "Recording folder to create")->required();
  room->add_option("--frames", o.frames, "Number of frames (30 per second)")->default_val(o.frames)->check(CLI::Range(1, 1000000));
  room->add_option("--seed", o.seed, "Seed of the camera path and the noise")->default_val(o.seed);
  room->add_option("--motion-blur", o.motion_blur_samples, "Renders averaged over the exposure per frame (0 = off)")
      ->default_val(o.motion_blur_samples)
      ->check(CLI::Range(0, 64));
  room->add_option("--exposure", o.exposure_s, "Exposure time spanned by motion blur, seconds")->default_val(o.exposure_s);
  room->add_option("--noise", o.noise_sigma, "Gaussian sensor noise, standard deviation in grey levels (0 = off)")
      ->default_val(o.noise_sigma);
  room->add_option("--size", args->size, "Frame size WxH, e.g. 1280x720 or 1920x1080 (field of view kept)")
      ->default_val(args->size)
      ->check(FrameSizeCheck({64, 48}, {7680, 4320}));
  room->add_option("--subset", o.frames_subset,
                   "Render only these frames of the --frames-long walk, e.g. 0-649:8,650-949 (a sparse lap to map, a "
                   "dense stretch to track); each exactly as in the whole recording");
  room->add_option("--jpeg", o.jpeg_quality, "Write frames as JPEG at this quality, 1..100 (0 = PNG)")
      ->default_val(o.jpeg_quality)
      ->check(CLI::Range(0, 100));
  room->add_option("--gain-drift", o.gain_drift,
                   "Exposure/gain change over time: brightness x (1 + A sin(2 pi t / 7 s)), A in [0, 1) (0 = off)")
      ->default_val(o.gain_drift);
  room->add_option("--rolling-shutter", o.rolling_shutter_s,
                   "Rolling-shutter readout time top to bottom, seconds (0 = global shutter)")
      ->default_val(o.rolling_shutter_s);
  room->add_option("--still", o.still_s,
                   "A tripod: the camera stops for this many seconds (sensor noise and compression as on every frame), "
                   "then walks on; the recording is that much longer (0 = none)")
      ->default_val(o.still_s)
      ->check(CLI::Range(0.0, 3600.0));
  room->add_option("--still-at", o.still_at_s, "Where the walk stops for --still: the walk's time, seconds")
      ->default_val(o.still_at_s)
      ->check(CLI::Range(0.0, 1e6));
  room->add_option("--walkers", o.walkers.count,
                   "People walking through: 1 to 3 of the built-in figure pacing circles round the orbit's character "
                   "spot (the room's centre on --path room), between the camera and the walls, in front of the "
                   "character; walkers.txt gives the share of each frame they cover (0 = none)")
      ->default_val(o.walkers.count)
      ->check(CLI::Range(0, synth::kMaxWalkers));
  room->add_option("--walkers-from", o.walkers.from_s,
                   "When the walkers appear, seconds into the recording (e.g. the second lap, so the mapped first lap has none)")
      ->default_val(o.walkers.from_s)
      ->check(CLI::Range(0.0, 1e6));
  room->add_option("--lamp-off", o.lights.lamp_off_s,
                   "Switch the room's lamp off at this time, seconds: every surface at a quarter of its light (-2 EV in one frame)")
      ->check(CLI::Range(0.0, 1e6));
  room->add_option("--lamp-on", o.lights.lamp_on_s, "Switch the lamp back on at this time, seconds (after --lamp-off)")
      ->check(CLI::Range(0.0, 1e6));
  room->add_flag("--sun", o.lights.sun,
                 "Sunlight through the window (--light window) falls on the floor, walls and boxes (+1 EV), moving as the "
                 "sun's azimuth sweeps 60 degrees over the recording");
  room->add_flag("--auto-exposure", o.lights.auto_exposure,
                 "The camera re-exposes after the lamp changes: 1/3 EV steps every 4 frames, from 0.3 s after the change");
  AddGlFlags(room, args->gl);
  room->add_option("--data", args->data_dir, "Folder with the photos (Debian package opencv-doc)")->default_val(args->data_dir);
  room->add_option("--path", o.walk,
                   "Camera walk: room (round the room's centre, looking at the walls) or orbit (two laps round the "
                   "demo's character spot: the first looking across the room, the second at the character)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, synth::RoomWalk>{{"room", synth::RoomWalk::kRoom},
                                                                                   {"orbit", synth::RoomWalk::kOrbit}}))
      ->default_str("room");
  room->add_option("--light", o.light,
                   "How the room is lit: even (from all round, a light floor) or window (daylight through a window, a "
                   "dark floor: a light with a direction, as the demo uses)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, synth::SynthLighting>{{"even", synth::SynthLighting::kEven},
                                                                                    {"window", synth::SynthLighting::kWindow}}))
      ->default_str("even");
  room->add_option("--board", args->board,
                   "Lay a printed chessboard flat on the floor: its inner corners, COLUMNSxROWS (e.g. 9x6), for a map "
                   "made metric and upright with 'arview map --board'")
      ->check(BoardSizeCheck());
  room->add_option("--square", o.board.square, "The board's square side, metres")
      ->default_val(o.board.square)
      ->check(CLI::Range(0.005, 1.0));
  room->add_option("--focal-scale", o.focal_scale,
                  "Another lens: the camera's focal length times this (0.7: wider), the frame size kept")
      ->default_val(o.focal_scale)
      ->check(CLI::Range(0.25, 4.0));
  room->add_option("--distortion", args->distortion,
                   "The lens's distortion, OpenCV's k1,k2,p1,p2,k3 (fewer: the rest 0); written to camera.yaml")
      ->delimiter(',')
      ->expected(1, 5)
      ->check(CLI::Range(-10.0, 10.0));
  room->add_option("--board-at", args->board_at,
                   "The board's centre on the floor, X,Y in metres (default: 1.1 m beside the orbit's character spot, or the "
                   "room's centre)")
      ->expected(2)
      ->delimiter(',')
      ->check(CLI::Range(-3.0, 3.0));
  room->add_option("--board-yaw", args->board_yaw_deg, "The board's turn about the vertical, degrees")
      ->default_val(args->board_yaw_deg)
      ->check(CLI::Range(-360.0, 360.0));
  room->add_flag("--force", o.overwrite, "Replace a recording already in --out");
  room->add_flag("--quiet", args->quiet, "No progress on stderr");
  room->callback([args] { RunSynthRoom(*args); });
  AddSynthVenueCommand(synth);
}

}  // namespace arview::app
