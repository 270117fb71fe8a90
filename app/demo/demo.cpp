#include "app/demo/demo.h"

#include "base/cache_folder.h"

#include <Eigen/Geometry>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "anim/character_bounds.h"
#include "anim_authoring/character_builder.h"
#include "anim_authoring/import.h"
#include "anim_authoring/scene.h"
#include "app/demo/demo_exchange.h"
#include "app/demo/demo_figures.h"
#include "app/pipeline/pipeline_report.h"
#include "app/placement/place_character.h"
#include "app/placement/scene_lighting.h"
#include "app/session/ar_session.h"
#include "base/atomic_file.h"
#include "base/cancellation.h"
#include "base/image_file.h"
#include "base/input_guard.h"
#include "base/progress.h"
#include "base/stats.h"
#include "mapping/colmap_pipeline.h"
#include "recordings/accuracy.h"
#include "render/ar_renderer.h"
#include "render/prt_cache.h"
#include "synth/synth_room.h"

namespace arview::app {

namespace {

namespace fs = std::filesystem;

constexpr int kSteps = 7;
void Step(int n, const std::string& what) { std::printf("\n[%d/%d] %s\n", n, kSteps, what.c_str()); std::fflush(stdout); }

// The printed chessboard on the floor beside the character's spot, from which the map takes its
// metres and its up (`arview map --board`): 9x6 inner corners of 8 cm squares (0.96 x 0.72 m
// with its margin), 1.1 m along +x from the spot, where the first lap sees it whole.
synth::FloorBoard DemoBoard(const synth::OrbitWalkOptions& orbit) {
  synth::FloorBoard board;
  board.inner_corners = {9, 6};
  board.square = 0.08;
  board.centre = orbit.subject + Eigen::Vector2d(1.1, 0);
  return board;
}
constexpr const char* kBoardInHeader = "chessboard 9x6 of 0.08 m squares";

// A recording already in `dir` is reused only when it is this walk: the window-lit room with the
// board (its ground truth's header says so; earlier demos rendered other rooms), same frame count
// and the same ground-truth poses (checked on a few frames), so a changed walk is never
// replayed stale.
bool HoldsWalk(const recordings::Recording& r, int frames, const synth::OrbitWalk& walk, double fps, cv::Size size) {
  if (r.camera.Size() != size) return false;
  const std::string groundtruth = ReadFileUpTo(r.root / "groundtruth.txt", 1 << 20);
  const std::string header = groundtruth.substr(0, groundtruth.find('\n'));
  if (header.find("window light") == std::string::npos || header.find(kBoardInHeader) == std::string::npos) return false;
  if (static_cast<int>(r.frames.size()) != frames || !r.groundtruth || static_cast<int>(r.groundtruth->size()) != frames) return false;
  for (int i : {0, frames / 3, frames / 2, frames - 1}) {
    const calib::Pose expected = walk.At(i / fps);
    const calib::Pose& stored = (*r.groundtruth)[i].pose;
    if ((expected.Center() - stored.Center()).norm() > 1e-4 || expected.q_cw.angularDistance(stored.q_cw) > 1e-4) return false;
  }
  return true;
}

recordings::Recording RenderWalk(const fs::path& dir, int frames, std::uint64_t seed, cv::Size size,
                                 const render::OffscreenOptions& gl, const CancellationToken& cancel) {
  synth::SynthRoomOptions o;
  o.width = size.width;
  o.height = size.height;
  const synth::OrbitWalk walk(frames / o.fps, seed, o.orbit);
  if (fs::exists(dir / "frames.txt")) {
    try {
      recordings::Recording existing = recordings::LoadRecording(dir);
      if (HoldsWalk(existing, frames, walk, o.fps, size)) {
        std::printf("  %s already holds this walk (%d frames): reused\n", dir.c_str(), frames);
        return existing;
      }
    } catch (const std::exception&) {
      // Not a usable recording: render it again.
    }
  }
  o.out = dir;
  o.frames = frames;
  o.seed = seed;
  o.walk = synth::RoomWalk::kOrbit;
  // Daylight through a window: a light the mapped lap sees, so the character casts a shadow.
  o.light = synth::SynthLighting::kWindow;
  o.board = DemoBoard(o.orbit);
  o.overwrite = true;
  o.gl = gl;  // Mesa reads the thread count once per process: the same as for the replay
  Progress progress("  rendering");
  const synth::SynthRoomReport r = synth::SynthesizeRoom(o, [&](int done, int total) {
    cancel.ThrowIfCancelled("stopped rendering the room after " + std::to_string(done) + " of " +
                            std::to_string(total) + " frames; a re-run renders it again");
    progress.Update(done, total);
  });
  progress.Finish();
  std::printf("  %d frames at %dx%d with exact ground truth -> %s\n", r.frames, size.width, size.height, dir.c_str());
  return recordings::LoadRecording(dir);
}

// The replayed lap read from uncompressed frames, as a camera delivers them: each PNG of the
// walk from `first` on converted once to BMP in `dir` (again when its PNG is newer). Decoding a
// 640x480 PNG took ~10 ms of CPU, a BMP 0.6 ms (docs/app.md): on two cores shared by
// tracking, rendering and encoding, the PNG decoder alone cost the replay a quarter of its
// frame rate. Same pixels, so the same tracking.
recordings::Recording WithUncompressedFrames(const recordings::Recording& walk, int first, const fs::path& dir,
                                             const CancellationToken& cancel) {
  recordings::Recording out = walk;
  fs::create_directories(dir);
  Progress progress("  uncompressed frames");
  const int total = static_cast<int>(walk.frames.size()) - first;
  int converted = 0;
  for (int i = first; i < static_cast<int>(walk.frames.size()); ++i) {
    const fs::path png = walk.FramePath(i);
    const fs::path bmp = fs::absolute(dir / png.filename().replace_extension(".bmp"));
    std::error_code ec;
    if (!fs::exists(bmp, ec) || fs::last_write_time(bmp, ec) < fs::last_write_time(png)) {
      cancel.ThrowIfCancelled("stopped converting the replayed frames; a re-run converts the rest");
      WriteImageAtomically(bmp, walk.ReadImage(i));
      ++converted;
    }
    out.frames[i].path = bmp.string();  // absolute: root / path is then the path itself
    progress.Update(i - first + 1, total);
  }
  progress.Finish();
  std::printf("  frames %d-%zu read uncompressed from %s (%d converted now)\n", first, walk.frames.size() - 1,
              dir.c_str(), converted);
  return out;
}

// The character's anchor in the map: standing on the walk's spot (room coordinates), upright,
// facing `facing_azimuth` (radians, room frame), `height` metres tall; `to_room` maps the map
// into the room (where the spot is), `map_units_per_metre` says how tall that is in the map.
Anchor AnchorInMap(const recordings::Sim3& to_room, const Eigen::Vector3d& spot, double facing_azimuth, double height,
                   double asset_height, double map_units_per_metre) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), forward(std::cos(facing_azimuth), std::sin(facing_azimuth), 0);
  Eigen::Matrix3d in_room;  // character frame (glTF: +X left, +Y up, +Z forward) → room
  in_room << up.cross(forward), up, forward;
  const recordings::Sim3 to_map = to_room.Inverse();
  Anchor a;
  a.position = to_map(spot);
  a.rotation = to_map.R * in_room;
  a.scale = height / asset_height * map_units_per_metre;
  return a;
}

// What the character does in the demo, from the clips the asset has: the idle synthesizer
// learned from its idle clips (the figure's Idle and WeightShift) under the view-adaptive
// look-at, and its Wave clip on the right arm when the viewer comes within `greet_within_map`
// (map units). An asset without such clips keeps the default schedule.
PlacedBehaviour DemoBehaviour(const anim::Character& asset, double greet_within_map) {
  PlacedBehaviour b;
  for (const char* clip : {"Idle", "WeightShift"})
    if (asset.FindClip(clip)) b.idle_clips.push_back(clip);
  if (asset.FindClip("Idle")) b.front_gesture = "point";  // a humanoid with authored arm clips
  if (asset.FindClip("Wave") && greet_within_map > 0) {
    b.greet_clip = "Wave";
    b.greet_within = greet_within_map;
  }
  // The greeting, spoken when the viewer is first seen, the wave on "hello" (a character that
  // cannot speak or wave says nothing).
  if (asset.FindClip("Wave") && asset.skeleton.FindMorphTarget("viseme_PP") >= 0)
    b.lines.push_back({"start", "<gaze at=\"viewer\"/>Oh, <gesture name=\"Wave\"/>hello! <face expr=\"happy\" intensity=\"0.6\"/>"
                                "I am standing right here in your room."});
  return b;
}

std::string BehaviourText(const PlacedBehaviour& b, double greet_within_m) {
  if (b.empty()) return "behaviour: the scene's default (its base clip looped under the look-at keys)";
  std::string text = "behaviour: ";
  if (!b.idle_clips.empty()) {
    text += "idles (synthesizer learned from";
    for (const std::string& c : b.idle_clips) text += " " + c;
    text += "), turns its body, spine, neck and head to look at the viewer";
    if (!b.front_gesture.empty()) text += ", points (" + b.front_gesture + " keys) at a viewer in front of it";
  } else {
    text += "looks at the viewer";
  }
  if (!b.lines.empty()) text += ", says hello (waving on the word) when it first sees the viewer";
  if (!b.greet_clip.empty()) {
    char line[96];
    std::snprintf(line, sizeof line, ", greets (%s) when the viewer comes within %.2f m", b.greet_clip.c_str(), greet_within_m);
    text += line;
  }
  return text + "; fades to idle while tracking is lost";
}

const char* Percent(std::size_t part, std::size_t whole, char* buffer, std::size_t size) {
  std::snprintf(buffer, size, "%zu/%zu (%.1f%%)", part, whole, 100.0 * part / std::max<std::size_t>(1, whole));
  return buffer;
}

// Step 3: the first lap's every `map_every`-th frame mapped with COLMAP, with a progress line.
mapping::MapBuildResult MapFirstLap(const recordings::Recording& walk, int half, const DemoOptions& o,
                                    const fs::path& work, const CancellationToken& cancel) {
  mapping::MapBuildOptions map_options;
  map_options.frames_spec = "0-" + std::to_string(half - 1) + ":" + std::to_string(o.map_every);
  map_options.matcher = mapping::MatcherKind::kSequential;
  // `arview map --preset fast --max-features 4096`: a rendered room at 640x480 has plenty of
  // texture; one orientation a feature and fewer bundle adjustments map its 96 frames in about
  // 70 s where two orientations and COLMAP's adjustments took 99 s (docs/mapping.md, "The demo's
  // room in 80 s"). 4096 features, not 2048: the second lap's registration error on four maps
  // of each, three RANSAC seeds each, median 0.424-0.463 px against 0.433-0.519 px and p95
  // 1.07-1.26 against 1.28-1.57 px, for ~5 s more (docs/tracker.md, "Seventh round").
  // Fewer features cost accuracy: 1536 gave 1.85 mm, 1024 2.61 mm.
  map_options.UseFastPreset();
  map_options.max_num_features = 4096;
  // arview's matcher for these sequential pairs, not `auto`'s COLMAP matcher for 640x480 frames:
  // on this room it maps 1.6x faster and no less exactly (2026-12-05, 96 frames: 132 s against
  // 211 s, keyframes 1.42 against 1.64 mm median; docs/mapping.md, "Matching"). `auto` keeps
  // COLMAP's for small frames because of templeRing's exhaustively matched photos.
  map_options.match_engine = mapping::MatchEngine::kArview;
  // Metres and up from the board on the floor, as a user with a printed board would map a room.
  const synth::FloorBoard board = DemoBoard(synth::OrbitWalkOptions{});
  map_options.scale.from = mapping::ScaleFrom::kBoard;
  map_options.scale.board = {board.inner_corners, board.square, true};
  map_options.cancel = cancel;
  Progress map_progress("  colmap");
  std::string stage_shown;
  mapping::MapBuildCallbacks callbacks;
  callbacks.progress = [&](const std::string& stage, int done, int total) {
    if (cancel.IsCancelled()) return;  // after a Ctrl-C: only the one line
    if (stage != stage_shown) {
      map_progress.Finish();
      map_progress = Progress("  colmap " + stage);
      stage_shown = stage;
    }
    map_progress.Update(done, total > 0 ? total : done);
  };
  callbacks.note = [&](const std::string& message) { std::printf("  %s\n", message.c_str()); };
  mapping::MapBuildResult built = mapping::BuildMap(walk, work / "map", map_options, callbacks);
  map_progress.Finish();
  double map_seconds = 0;
  for (const auto& t : built.timings) map_seconds += t.seconds;
  std::printf("  %zu of %zu frames registered, %zu points, %.1f s\n", built.map.keyframes.size(),
              built.selected_frames.size(), built.map.points.size(), map_seconds);
  if (!built.scale_failure.empty()) std::printf("  warning: the board gave no scale: %s\n", built.scale_failure.c_str());
  std::printf("  frame: %s (%s)\n", built.map.frame.metric() ? "metres, +z up" : "COLMAP's, no scale",
              built.map.frame.how.c_str());
  return built;
}

// The map lives in COLMAP's frame; the alignment to the room is fitted on the map's keyframes
// (first lap), never on the frames being judged (second lap).
recordings::Sim3 MapToRoom(const map::Map& map, const recordings::Recording& walk) {
  recordings::Trajectory keyframes;
  for (const auto& k : map.keyframes) keyframes.push_back({k.timestamp, k.pose});
  const recordings::Sim3 to_room = recordings::FitAlignment(keyframes, *walk.groundtruth, recordings::AlignMode::kSim3, 1e-3);
  // How right the map's own metres and up are: against the room's exact ones (a metric map's
  // alignment has scale 1 and keeps +z).
  if (map.frame.metric()) {
    const double up_error = std::acos(std::clamp((to_room.R * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0)) * 180 / M_PI;
    std::printf("  the map's metres against the room's exact ones: scale %.4f (%.2f%% off), up %.2f deg off\n",
                to_room.scale, 100 * std::abs(to_room.scale - 1), up_error);
  }
  return to_room;
}

// Map units per metre: 1 on a metric map (its own scale); otherwise the exact ground truth's,
// which only a rendered room has, said so.
double MapUnitsPerMetre(const map::Map& map, const recordings::Sim3& to_room) {
  if (map.frame.metric()) return 1.0;
  std::printf("  note: the map has no scale of its own; the character is sized from the room's exact ground truth\n");
  return to_room.Inverse().scale;
}

// Step 4: the character stood on the walk's spot, its scene file and its light written.
struct DemoCharacter {
  anim::Character asset;
  ScenePlacement placed;
  fs::path scene;
  double map_units_per_metre = 1;
};

DemoCharacter PlaceDemoCharacter(const DemoOptions& o, const map::Map& map, const recordings::Sim3& to_room,
                                 const synth::OrbitWalk& orbit, const fs::path& work) {
  DemoCharacter c{authoring::LoadCharacter(o.character), {}, work / "scene.yaml"};
  const double asset_height = anim::RestHeight(c.asset, Eigen::Vector3d::UnitY());
  if (!(asset_height > 0)) throw Error(o.character + ": the character has no height to scale");
  PlaceCharacterOptions place_options;
  // The figure idles under its look-at keys; BCN_Epileptic's only clip is a seizure on the
  // floor, so its keys are built on the rest pose; other assets use their first clip.
  if (c.asset.FindClip("Idle")) place_options.base_clip = "Idle";
  else if (o.character.find("BCN_Epileptic") != std::string::npos) place_options.base_clip = "rest";
  const double map_units_per_metre = MapUnitsPerMetre(map, to_room);
  c.map_units_per_metre = map_units_per_metre;
  place_options.anchor =
      AnchorInMap(to_room, orbit.Subject(), orbit.CloseApproachAzimuth(), o.height, asset_height, map_units_per_metre);
  c.placed = PlaceCharacter(map, o.character, place_options);
  c.placed.comment = "arview demo: " + c.placed.asset.filename().string() + " where the demo's walk circles";
  c.placed.behaviour = DemoBehaviour(c.asset, o.greet_within * map_units_per_metre);
  WriteSceneFile(c.placed, c.scene);
  // The room's light at the character, from the map's keyframe images (room/room_light.h):
  // SH lighting with per-vertex PRT and the cast shadow in the replay.
  WritePlacedLight(map, work / "map", work / "walk", c.placed, c.scene);
  std::printf("  %s, %.2f m tall, at (%.2f, %.2f) m in the room, facing where the viewer comes close; keys built on %s "
              "-> %s\n",
              c.placed.name.c_str(), o.height, orbit.Subject().x(), orbit.Subject().y(),
              c.placed.base_clip.empty() ? "its first clip" : c.placed.base_clip.c_str(), c.scene.c_str());
  std::printf("  %s\n", BehaviourText(c.placed.behaviour, o.greet_within).c_str());
  return c;
}

// Step 4's exchange (issue 54): the dialogue and the visitor's questions written into the work
// folder, for a character that speaks (as the greeting's line is given).
std::optional<DemoExchange> PrepareExchange(const DemoCharacter& character, const fs::path& work) {
  if (character.placed.behaviour.lines.empty()) {
    std::printf("  no scripted exchange: the character cannot speak\n");
    return std::nullopt;
  }
  DemoExchange exchange = WriteDemoExchange(work);
  std::string asked;
  for (std::size_t i = 0; i < VisitorLines().size(); ++i) {
    char line[160];
    std::snprintf(line, sizeof line, "%s\"%s\" at %.1f s", i ? ", " : "", VisitorLines()[i].text.c_str(),
                  VisitorLines()[i].start_s);
    asked += line;
  }
  std::printf("  a visitor (Flite's %s voice) asks %s into the replay -> %s; the character answers through %s\n",
              ToString(kVisitorVoice).c_str(), asked.c_str(), exchange.wav.c_str(), exchange.dialogue.c_str());
  return exchange;
}

// Step 7's line on the exchange: which questions were heard as said and answered, and how soon.
void ReportExchange(const PipelineReport& replayed, const fs::path& work) {
  std::size_t answered = 0;
  std::string latencies;
  for (std::size_t i = 0; i < VisitorLines().size(); ++i) {
    const auto turn = std::find_if(replayed.dialogue_turns.begin(), replayed.dialogue_turns.end(),
                                   [&](const DialogueTurnRecord& t) { return t.heard == VisitorLines()[i].text; });
    if (turn == replayed.dialogue_turns.end() || turn->reply_start_s < 0) continue;
    ++answered;
    char latency[32];
    std::snprintf(latency, sizeof latency, "%s%.2f", latencies.empty() ? "" : ", ", turn->LatencyS());
    latencies += latency;
  }
  std::printf("  the visitor's questions (%s): %zu of %zu heard as said and answered%s\n", (work / "visitor.wav").c_str(),
              answered, VisitorLines().size(),
              latencies.empty() ? "" : ("; replies " + latencies + " s after the words, on the replay's frame clock").c_str());
}

// Step 5: the second lap through the whole pipeline into the video.
SessionResult ReplaySecondLap(const DemoOptions& o, const recordings::Recording& walk, const map::Map& map,
                              const fs::path& scene, const std::optional<DemoExchange>& exchange, const fs::path& out,
                              const render::OffscreenOptions& gl, const fs::path& work, int half,
                              const CancellationToken& cancel) {
  SessionOptions session;
  session.scene_file = scene;
  PendingOutput video(out);
  session.sink = video.sink_target();
  session.sink_fps = MedianFrameRate(walk.frames);
  session.trajectory_out = work / "trajectory.txt";
  session.stats_out = work / "stats.json";
  session.compositor.gl = gl;
  session.compositor.hmd = o.hmd;
  session.compositor.hud = !o.no_hud;
  session.compositor.ar.antialiasing = render::ParseAntialiasing(o.aa);
  const SceneLighting lighting = ResolveSceneLighting(scene, "auto", {});
  session.compositor.ar.lighting = lighting.mode;
  session.compositor.ar.prt_cache_folder = render::DefaultPrtCacheFolder();
  session.tracker.index_cache_folder = CacheFolder("descriptor-index");
  session.compositor.room_light = lighting.light;
  session.expected_frames = o.frames - half;
  session.cancel = cancel;
  session.output_name = out.string();
  session.audio_track = true;  // the greeting spoken in the video, the visitor's questions and the replies
  if (exchange) {
    // `replay --dialogue --audio-in`: the visitor's WAV heard on the replay's frame clock.
    session.dialogue.dialogue_file = exchange->dialogue;
    session.dialogue.audio_in = exchange->wav;
  }
  recordings::ReplayOptions replay;
  for (int i = half; i < o.frames; ++i) replay.frames.push_back(i);
  const recordings::Recording replayed = WithUncompressedFrames(walk, half, work / "replay-frames", cancel);
  session.frame_camera = RecordingTrackingCamera(map.camera, walk.camera);
  session.recording = &walk;  // the walk the map was built from: its keyframes' images
  recordings::RecordingSource source(replayed, replay);
  SessionResult result = RunSession(source, walk.camera.Size(), map, (work / "map").string(), session);
  video.Commit();
  std::printf("%s%s%s", PipelineReportText(result.report).c_str(), result.loss_advice.c_str(),
              SoundSummaryText(result.sound).c_str());
  return result;
}

// Step 6: the replayed trajectory, in the room's frame, against the exact ground truth.
recordings::AccuracyReport ReportAccuracy(const PipelineReport& replayed, const recordings::Sim3& to_room,
                                          const recordings::Trajectory& second_lap, const fs::path& work) {
  recordings::AccuracyOptions accuracy;
  accuracy.align = recordings::AlignMode::kNone;
  accuracy.max_dt = 1e-3;
  const recordings::AccuracyReport report =
      recordings::EvaluateTrajectory(recordings::TransformTrajectory(replayed.trajectory, to_room), second_lap, accuracy);
  recordings::PlotTrajectories(report, second_lap, work / "trajectory.png");
  char buffer[64];
  std::printf("  localized %s frames\n", Percent(replayed.frames_localized, replayed.frames_processed, buffer, sizeof buffer));
  std::printf("  camera centre error: median %.1f mm, RMSE %.1f mm, max %.1f mm; rotation median %.2f deg\n",
              1000 * report.ate.median, 1000 * report.ate.rmse, 1000 * report.ate.max, report.rotation_deg.median);
  return report;
}

// Of the replayed frames in which the character is in view, how many have its head within 20
// degrees of the camera: {within, in view}.
std::pair<std::size_t, std::size_t> GazeWithin20Deg(const PipelineReport& replayed, const recordings::Trajectory& second_lap,
                                                    const InViewSummary& view) {
  std::size_t gaze_frames = 0, gaze_within = 0;
  std::map<double, bool> in_view_at;
  for (std::size_t i = 0; i < second_lap.size(); ++i) in_view_at[second_lap[i].timestamp] = view.per_frame[i];
  for (const FrameLog& f : replayed.frames) {
    if (!f.gaze_error_deg || !in_view_at[f.timestamp]) continue;
    ++gaze_frames;
    gaze_within += *f.gaze_error_deg <= 20.0;
  }
  return {gaze_within, gaze_frames};
}

// When the distance trigger fired, and how close the viewer was: "frame 1003 (1.37 m)".
std::vector<std::string> Greetings(const PipelineReport& replayed, const recordings::Trajectory& second_lap,
                                   const Eigen::Vector3d& spot) {
  std::vector<std::string> greetings;
  for (const FrameLog& f : replayed.frames) {
    if (!f.actions_triggered) continue;
    const auto it = std::find_if(second_lap.begin(), second_lap.end(),
                                 [&](const recordings::StampedPose& g) { return std::abs(g.timestamp - f.timestamp) < 1e-3; });
    char at[64];
    std::snprintf(at, sizeof at, "frame %lld (%.2f m)", static_cast<long long>(f.index),
                  it == second_lap.end() ? 0.0 : (it->pose.Center() - spot).head<2>().norm());
    greetings.push_back(at);
  }
  return greetings;
}

// The close-up of the contact sheet: the character's face from 0.6 m, on the line from its eyes
// to where the viewer was at a moment of the replay when the eyes met the viewer's.
struct FaceCloseUp {
  cv::Mat image;  // the camera's size, the face at its centre
  long long frame = -1;
  double time = 0;        // seconds into the replay (the animation's time)
  double viewer_m = 0;    // how far the viewer was from the eyes then
  bool eyes_on_viewer = false, blinking = false;
};

constexpr double kCloseUpMetres = 0.6;

// The midpoint of the eyes, in the map.
Eigen::Vector3d EyesCentre(const anim::PlacedCharacter& c, const anim::AnimatorFrame& f) {
  const anim::GazeRig& rig = c.gaze()->rig;
  const Eigen::Vector3d model = 0.5 * (f.model[rig.eyes[0].eye].block<3, 1>(0, 3) + f.model[rig.eyes[1].eye].block<3, 1>(0, 3));
  return (c.placement().ModelToMap() * model.homogeneous()).head<3>();
}

// A camera at `centre` looking at `target`, `up` (map) up in its picture.
calib::Pose LookingAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = (-up).cross(z).normalized();  // the camera's y points down
  Eigen::Matrix3d camera_to_map;
  camera_to_map << x, z.cross(x), z;
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(camera_to_map), centre);
}

// The video frame (the replay's processing order: a replay drops none) in which the first
// character's mouth is open widest while it speaks; none if it never speaks.
std::optional<int> MouthMostOpen(const PipelineReport& report) {
  std::optional<int> widest;
  float widest_open = 0;
  for (std::size_t i = 0; i < report.frames.size(); ++i) {
    const anim::FaceFrame& face = report.frames[i].face;
    if (face.talking > 0 && face.jaw_open > widest_open) {
      widest_open = face.jaw_open;
      widest = static_cast<int>(i);
    }
  }
  return widest;
}

// The replayed frames in which the eyes met the viewer's, not blinking, nearest viewer first.
std::vector<const FrameLog*> EyeContactFrames(const PipelineReport& report, const Eigen::Vector3d& character_map) {
  std::vector<const FrameLog*> frames;
  for (const FrameLog& f : report.frames)
    if (f.eyes.eyes_on_viewer && !f.eyes.blinking && f.track.status != tracker::TrackStatus::kLost) frames.push_back(&f);
  std::stable_sort(frames.begin(), frames.end(), [&](const FrameLog* a, const FrameLog* b) {
    return (a->track.center - character_map).norm() < (b->track.center - character_map).norm();
  });
  return frames;
}

// The scene's character (its view-adaptive keys and gaze, without the demo's idle layer: the body
// is the keys' pose, the eyes the demo's, the same seed at the same time) at the nearest moment
// of eye contact where it keeps the eyes on a camera 0.6 m from them, rendered in the scene's
// light on grey. None for a character without eyes, or no such moment.
std::optional<FaceCloseUp> RenderFaceCloseUp(const DemoCharacter& character, const PipelineReport& report,
                                             const calib::Camera& camera, const render::OffscreenOptions& gl) {
  const authoring::Scene scene = authoring::LoadScene(character.scene);
  authoring::AnimatedCharacter c(scene.characters.at(0));
  if (!c.gaze() || report.frames.empty()) return std::nullopt;
  const anim::Placement& placement = c.placement();
  const Eigen::Vector3d up = placement.UpInMap().normalized();
  const double first_time = report.frames.front().timestamp;
  const std::vector<const FrameLog*> candidates = EyeContactFrames(report, placement.ModelToMap().block<3, 1>(0, 3));
  for (std::size_t i = 0; i < std::min<std::size_t>(candidates.size(), 100); ++i) {
    const FrameLog& f = *candidates[i];
    const double t = f.timestamp - first_time;
    const Eigen::Vector3d viewer = f.track.center;
    const Eigen::Vector3d eyes = EyesCentre(c, c.Update(placement.ViewpointFromCamera(viewer), t, placement.MapToModel(viewer)));
    const Eigen::Vector3d camera_centre = eyes + kCloseUpMetres * character.map_units_per_metre * (viewer - eyes).normalized();
    const anim::AnimatorFrame& frame =
        c.Update(placement.ViewpointFromCamera(camera_centre), t, placement.MapToModel(camera_centre));
    if (!frame.gaze.eyes_on_viewer || frame.gaze.blinking) continue;
    FaceCloseUp close{{}, f.index, t, (viewer - eyes).norm() / character.map_units_per_metre, true, false};
    auto context = render::OffscreenContext::Create(gl);
    const SceneLighting lighting = ResolveSceneLighting(character.scene, "auto", {});
    render::ArOptions options;
    options.lighting = lighting.mode;
    options.prt_cache_folder = render::DefaultPrtCacheFolder();
    options.exposure_smoothing = 1.0;  // one frame: its own exposure
    render::ArRenderer renderer(*context, camera, options);
    if (lighting.light) renderer.SetRoomLight(*lighting.light);
    renderer.AddCharacter(c.character(), placement);
    const anim::AnimatorFrame* frames[] = {&frame};
    close.image = renderer.Render(cv::Mat(), LookingAt(camera_centre, EyesCentre(c, frame), up), frames);
    return close;
  }
  return std::nullopt;
}

// Step 7: what a viewer sees. The character drawn where tracking placed it: its rest pose placed
// in the room by the scene's anchor and the map-to-room alignment, seen from the ground-truth
// camera of every replayed frame that was localized (a lost frame shows the video alone).
void ReportWhatAViewerSees(const DemoOptions& o, const recordings::Recording& walk, const DemoCharacter& character,
                           const recordings::Sim3& to_room, const synth::OrbitWalk& orbit, const SessionResult& result,
                           const recordings::AccuracyReport& report, const recordings::Trajectory& second_lap,
                           bool exchanged, const fs::path& out, const fs::path& work) {
  const authoring::Scene loaded = authoring::LoadScene(character.scene);
  const CharacterMarkers markers = MarkersOf(character.asset, to_room.Matrix() * loaded.characters[0].placement().ModelToMap());
  std::map<double, bool> localized;
  for (const FrameLog& f : result.report.frames) localized[f.timestamp] = f.track.status != tracker::TrackStatus::kLost;
  std::vector<std::optional<calib::Pose>> seen_from;
  for (const auto& g : second_lap) {
    const auto it = localized.find(g.timestamp);
    seen_from.push_back(it != localized.end() && it->second ? std::optional<calib::Pose>(g.pose) : std::nullopt);
  }
  const InViewSummary view = MeasureInView(walk.camera, seen_from, markers);
  const auto [gaze_within, gaze_frames] = GazeWithin20Deg(result.report, second_lap, view);
  const std::vector<std::string> greetings = Greetings(result.report, second_lap, orbit.Subject());
  std::vector<double> distances;
  for (const auto& g : second_lap) distances.push_back((g.pose.Center() - orbit.Subject()).head<2>().norm());
  const fs::path sheet_file = out.parent_path() / "contact_sheet.png";
  const double seconds = result.report.frames.empty() ? 0.0 : result.report.frames.back().timestamp - result.report.frames.front().timestamp;
  const std::optional<int> open_mouth = MouthMostOpen(result.report);
  cv::Mat sheet = ContactSheet(out, 12, 4, 320, open_mouth);
  const std::optional<FaceCloseUp> close_up = RenderFaceCloseUp(character, result.report, walk.camera, o.gl);
  if (close_up) {
    char lines[4][96];
    std::snprintf(lines[0], sizeof lines[0], "the face from %.1f m, eyes on the viewer", kCloseUpMetres);
    std::snprintf(lines[1], sizeof lines[1], "frame %lld (%.2f s), the viewer %.2f m away", close_up->frame, close_up->time,
                  close_up->viewer_m);
    std::snprintf(lines[2], sizeof lines[2], "eye contact in %.0f%% of the lap's frames,",
                  100.0 * result.report.eye_contact_frames / std::max<std::size_t>(1, result.report.eye_frames));
    std::snprintf(lines[3], sizeof lines[3], "%ld blinks (%.1f a minute)", result.report.blinks,
                  seconds > 0 ? 60.0 * result.report.blinks / seconds : 0.0);
    sheet = WithCloseUp(sheet, close_up->image, 320, 240, {lines[0], lines[1], lines[2], lines[3]});
  }
  WriteImageAtomically(sheet_file, sheet);

  char buffer[64];
  const double latency = result.report.stages.count("latency") ? result.report.stages.at("latency").median : 0.0;
  std::printf("\nFigures (second lap, %zu frames; this machine, shared with other work):\n", view.frames);
  std::printf("  character in view (head and hips in the picture): %s\n", Percent(view.in_view, view.frames, buffer, sizeof buffer));
  std::printf("  its height in the picture when in view: median %.0f%%, smallest %.0f%%; at least a fifth in %s\n",
              100 * view.median_height_fraction, 100 * view.min_height_fraction,
              Percent(view.at_least_a_fifth, view.in_view, buffer, sizeof buffer));
  std::printf("  head within 20 deg of the camera, frames in view: %s\n", Percent(gaze_within, gaze_frames, buffer, sizeof buffer));
  if (result.report.eye_frames > 0) {
    std::printf("  eyes on the viewer's (mutual gaze), frames with eyes: %s; blinks: %ld (%.1f a minute)\n",
                Percent(result.report.eye_contact_frames, result.report.eye_frames, buffer, sizeof buffer), result.report.blinks,
                seconds > 0 ? 60.0 * result.report.blinks / seconds : 0.0);
    if (close_up)
      std::printf("  close-up for the contact sheet: frame %lld (%.2f s), the face from %.1f m, eyes on the camera\n",
                  close_up->frame, close_up->time, kCloseUpMetres);
    else
      std::printf("  close-up for the contact sheet: none (no frame kept the eyes on a camera at %.1f m)\n", kCloseUpMetres);
  }
  if (open_mouth)
    std::printf("  open mouth for the contact sheet: frame %d, the widest while it speaks (jaw at %.0f%% of jawOpen)\n", *open_mouth,
                100.0 * result.report.frames[static_cast<std::size_t>(*open_mouth)].face.jaw_open);
  std::printf("  the viewer's distance to the character: median %.2f m, %.2f to %.2f m\n", Median(distances),
              *std::min_element(distances.begin(), distances.end()), *std::max_element(distances.begin(), distances.end()));
  const ScenePlacement& placed = character.placed;
  if (!placed.behaviour.greet_clip.empty()) {
    std::string when;
    for (const std::string& g : greetings) when += (when.empty() ? " at " : ", ") + g;
    std::printf("  greetings (%s when the viewer came within %.2f m): %zu%s\n", placed.behaviour.greet_clip.c_str(),
                o.greet_within, greetings.size(), when.c_str());
  }
  if (exchanged) ReportExchange(result.report, work);
  std::printf("  tracking: %zu/%zu localized, centre error median %.1f mm, latency median %.1f ms\n",
              result.report.frames_localized, result.report.frames_processed, 1000 * report.ate.median, latency);
  std::printf("  end to end: %.1f frames per second at %dx%d\n", result.report.fps, walk.camera.width, walk.camera.height);
  std::printf("\nwrote %s\n      %s (12 frames%s), %s (plot), %s, %s, %s%s\n", out.c_str(), sheet_file.c_str(),
              close_up ? " and the face's close-up" : "",
              (work / "trajectory.png").c_str(), (work / "trajectory.txt").c_str(), (work / "stats.json").c_str(),
              character.scene.c_str(),
              exchanged ? (", " + (work / "dialogue.yaml").string() + ", " + (work / "visitor.wav").string()).c_str() : "");
}

}  // namespace

void RunDemo(const DemoOptions& o) {
  const fs::path work = o.work;
  fs::create_directories(work);
  const fs::path out = o.out.empty() ? work / "demo.mp4" : fs::path(o.out);
  const render::OffscreenOptions& gl = o.gl;
  const ScopedSignalCancellation signals;

  Step(1, "Rendering a walk of two laps round the character's spot, with exact ground truth");
  const recordings::Recording walk = RenderWalk(work / "walk", o.frames, 1, cv::Size(o.frame_width, o.frame_height), gl, signals.token());
  const int half = o.frames / 2;
  const synth::OrbitWalk orbit(o.frames / 30.0, 1, synth::OrbitWalkOptions{});

  Step(2, "Checking the recording");
  std::printf("  frames 0-%d (first lap, looking across the room) build the map; frames %d-%d (second lap, round the "
              "character: behind it, a fast glance away, close to it once) are tracked\n",
              half - 1, half, o.frames - 1);

  Step(3, "Mapping the first lap with COLMAP");
  const mapping::MapBuildResult built = MapFirstLap(walk, half, o, work, signals.token());
  const recordings::Sim3 to_room = MapToRoom(built.map, walk);

  Step(4, "Standing the character on the walk's spot with 8 look-at keys");
  const DemoCharacter character = PlaceDemoCharacter(o, built.map, to_room, orbit, work);
  const std::optional<DemoExchange> exchange = PrepareExchange(character, work);

  Step(5, "Replaying the second lap: track, animate, render, composite");
  const SessionResult result =
      ReplaySecondLap(o, walk, built.map, character.scene, exchange, out, gl, work, half, signals.token());

  Step(6, "Tracking accuracy against the exact ground truth");
  const recordings::Trajectory second_lap(walk.groundtruth->begin() + half, walk.groundtruth->end());
  const recordings::AccuracyReport report = ReportAccuracy(result.report, to_room, second_lap, work);

  Step(7, "What a viewer sees");
  ReportWhatAViewerSees(o, walk, character, to_room, orbit, result, report, second_lap, exchange.has_value(), out, work);
}

}  // namespace arview::app
