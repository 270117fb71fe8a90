// arview eval <estimate.txt> <groundtruth.txt> [--align sim3|se3|none] [--align-with <poses.txt>]
//             [--plot plot.png] [--json] [--max-dt S] [--rpe-delta N]
//             [--camera camera.yaml (--scene scene.yaml | --points points.txt | --room-points)]
//             [--smoothed stats.json]

#include <algorithm>
#include <fstream>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/cli/commands.h"
#include "app/cli/registration_points.h"
#include "base/geometry.h"
#include "calib/camera.h"
#include "recordings/accuracy.h"
#include "recordings/registration.h"
#include "synth/synth_room.h"

namespace arview::app {

namespace {

struct EvalArgs {
  std::string estimate;
  std::string groundtruth;
  std::string align = "sim3";
  std::string align_with;
  std::string plot;
  bool json = false;
  double max_dt = 0.02;
  int rpe_delta = 1;
  std::string camera;
  std::string scene;
  std::string points;
  std::string smoothed;
  bool room_points = false;
  std::string room_photos = synth::kOpenCvDocData;
  double over_px = 5.0;
};

// The smoothed centres of the frames in a stats.json of `arview replay` or `arview track`
// (each localized frame's `timestamp` and `smoothed_center`), in time order.
std::vector<recordings::StampedCentre> ReadSmoothedCentres(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw CommandError(file + ": cannot read the stats file (--smoothed)");
  nlohmann::json stats;
  try {
    stats = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw CommandError(file + ": not a finished stats.json (--smoothed): " + e.what());
  }
  std::vector<recordings::StampedCentre> centres;
  if (stats.contains("frames") && stats["frames"].is_array()) {
    for (const nlohmann::json& frame : stats["frames"]) {
      if (!frame.contains("smoothed_center") || !frame.contains("timestamp")) continue;
      const auto& c = frame["smoothed_center"];
      centres.push_back({frame["timestamp"].get<double>(), {c[0].get<double>(), c[1].get<double>(), c[2].get<double>()}});
    }
  }
  if (centres.empty()) {
    throw CommandError(file + ": no frame has a smoothed_center (--smoothed takes the --stats file of replay or track)");
  }
  std::sort(centres.begin(), centres.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  return centres;
}

// What the registration measures need beside the two trajectories: the camera, the scene's
// points, the smoothed centres. Recall needs none of them.
recordings::RegistrationOptions RegistrationInputs(const EvalArgs& args, std::vector<recordings::StampedCentre>& smoothed) {
  recordings::RegistrationOptions options;
  options.over_px = args.over_px;
  if (!args.scene.empty()) options.points = SceneMarks(args.scene);
  if (!args.points.empty()) {
    const std::vector<Eigen::Vector3d> listed = ReadPointsFile(args.points);
    options.points.insert(options.points.end(), listed.begin(), listed.end());
  }
  if (args.room_points) options.groundtruth_points = RoomGeometryPoints(args.groundtruth, args.room_photos);
  if (!args.smoothed.empty()) {
    smoothed = ReadSmoothedCentres(args.smoothed);
    options.smoothed = &smoothed;
  }
  return options;
}

// An alignment needs positions that span at least a plane (base/geometry.h EstimateSim3). Each
// trajectory the alignment is fitted on is checked by itself first, so that the error names
// the file whose camera centres are degenerate (all at one point, or on one line).
void RequireAlignablePositions(const recordings::Trajectory& trajectory, const std::string& file) {
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(trajectory.size());
  for (const auto& stamped : trajectory) centres.push_back(stamped.pose.Center());
  if (centres.size() < 3) return;  // the association's own error says how many are needed
  try {
    (void)EstimateSim3(centres, centres, false, "alignment");
  } catch (const Error& e) {
    throw CommandError(file + ": " + e.what());
  }
}

void RunEval(const EvalArgs& args) {
  try {
    const recordings::Trajectory estimate = recordings::ReadTum(args.estimate);
    const recordings::Trajectory groundtruth = recordings::ReadTum(args.groundtruth);
    if (estimate.empty()) throw CommandError(args.estimate + ": holds no poses");
    if (groundtruth.empty()) throw CommandError(args.groundtruth + ": holds no poses");
    std::optional<recordings::Trajectory> align_with;
    recordings::AccuracyOptions options;
    options.align = recordings::ParseAlignMode(args.align);
    options.max_dt = args.max_dt;
    options.rpe_delta = args.rpe_delta;
    if (!args.align_with.empty()) {
      if (options.align == recordings::AlignMode::kNone) {
        throw CommandError("--align-with needs --align se3 or sim3");
      }
      align_with = recordings::ReadTum(args.align_with);
      if (align_with->empty()) {
        throw CommandError(args.align_with + ": holds no poses (--align-with fits the alignment on its poses)");
      }
      options.align_with = &*align_with;
    }
    if (options.align != recordings::AlignMode::kNone) {
      RequireAlignablePositions(groundtruth, args.groundtruth);
      RequireAlignablePositions(align_with ? *align_with : estimate, align_with ? args.align_with : args.estimate);
    }
    const recordings::AccuracyReport report = recordings::EvaluateTrajectory(estimate, groundtruth, options);
    if (!args.plot.empty()) recordings::PlotTrajectories(report, groundtruth, args.plot);
    std::vector<recordings::StampedCentre> smoothed;
    const recordings::RegistrationOptions registration_options = RegistrationInputs(args, smoothed);
    const calib::Camera camera = args.camera.empty() ? calib::Camera{} : calib::LoadCamera(args.camera);
    const recordings::RegistrationReport registration =
        recordings::EvaluateRegistration(report, estimate, groundtruth, camera, registration_options);
    if (args.json) {
      nlohmann::ordered_json j = nlohmann::ordered_json::parse(recordings::ReportToJson(report));
      j["registration"] = nlohmann::ordered_json::parse(recordings::RegistrationToJson(registration));
      std::cout << j.dump(2) << "\n";
    } else {
      std::cout << recordings::ReportToText(report) << recordings::RegistrationToText(registration);
      if (!args.plot.empty()) std::cout << "plot        " << args.plot << "\n";
    }
  } catch (const recordings::RecordingError& e) {
    // The alignment's and association's errors concern a pair: both files are named. The
    // alignment is fitted on the --align-with file when there is one, not on the estimate.
    const std::string message = e.what();
    if (message.rfind("alignment", 0) == 0 && !args.align_with.empty()) {
      throw CommandError(args.align_with + " (--align-with) against " + args.groundtruth + ": " + message);
    }
    if (message.rfind("alignment", 0) == 0 || message.rfind("evaluation", 0) == 0 ||
        message.rfind("registration", 0) == 0) {
      throw CommandError(args.estimate + " against " + args.groundtruth + ": " + message);
    }
    throw CommandError(message);
  }
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "Compare a trajectory with ground truth (ATE, RPE, alignment, plot)");
  auto args = std::make_shared<EvalArgs>();
  cmd->add_option("estimate", args->estimate, "Estimated trajectory (TUM: timestamp tx ty tz qx qy qz qw, camera-to-world)")
      ->required();
  cmd->add_option("groundtruth", args->groundtruth, "Ground-truth trajectory (TUM)")->required();
  cmd->add_option("--align", args->align, "Alignment of the estimate to the ground truth")
      ->check(CLI::IsMember({"sim3", "se3", "none"}))
      ->capture_default_str();
  cmd->add_option("--align-with", args->align_with,
                  "Fit the alignment on this trajectory (e.g. the map's keyframe poses) instead of the estimate");
  cmd->add_option("--plot", args->plot, "Write a PNG: top and side view, error by colour");
  cmd->add_flag("--json", args->json, "Print the report as one JSON object");
  cmd->add_option("--max-dt", args->max_dt, "Timestamp association tolerance, seconds")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  cmd->add_option("--rpe-delta", args->rpe_delta, "RPE interval, in associated poses")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--camera", args->camera,
                  "The recording's camera.yaml: with --scene or --points, registration error in pixels and jitter");
  cmd->add_option("--scene", args->scene,
                  "Scene file: each character's anchor and its rest pose's bounding-box corners are projected (map frame)");
  cmd->add_option("--points", args->points, "Text file of points to project, x y z a line in the map's frame");
  cmd->add_option("--smoothed", args->smoothed,
                  "stats.json of replay or track: the smoothed centres, for the smoothing's lag and jitter");
  cmd->add_flag("--room-points", args->room_points,
                "On a room rendered by 'arview synth room': also score each frame on the points of the room's true "
                "surfaces its true camera sees (photo corners, edge midpoints, centres), as DCRE");
  cmd->add_option("--room-photos", args->room_photos, "With --room-points: the room's photos (opencv-doc's examples)")
      ->capture_default_str();
  cmd->add_option("--over-px", args->over_px, "Report the share of frames whose worst point is over this, pixels")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->callback([args] {
    if ((!args->scene.empty() || !args->points.empty() || args->room_points) && args->camera.empty()) {
      throw CommandError("--scene, --points and --room-points need --camera (the recording's camera.yaml)");
    }
    RunEval(*args);
  });
}

}  // namespace arview::app
