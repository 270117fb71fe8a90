// arview import <kind> <source> --out <recording> [--camera camera.yaml | --fov DEG] [--force]

#include <iostream>
#include <optional>

#include "app/cli/commands.h"
#include "calib/camera.h"
#include "recordings/importers.h"

namespace arview::app {

namespace {

struct ImportArgs {
  std::string kind;
  std::string source;
  std::string out;
  std::string camera;
  std::optional<double> fov;
  bool force = false;
};

void RunImport(const ImportArgs& args) {
  recordings::ImportOptions options;
  options.overwrite = args.force;
  if (!args.camera.empty()) {
    options.camera = calib::LoadCamera(args.camera);
  }
  options.horizontal_fov_deg = args.fov;
  const recordings::ImportResult r = recordings::Import(args.kind, args.source, args.out, options);
  for (const std::string& note : r.notes) std::cout << "note: " << note << "\n";
  std::cout << "imported " << r.frame_count << " frames (" << r.camera.width << "x" << r.camera.height
            << ", fx " << r.camera.fx << ", fy " << r.camera.fy << ")"
            << (r.has_groundtruth ? " with ground truth" : ", no ground truth") << " into " << args.out << "\n";
}

}  // namespace

void AddImportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("import", "Import a public dataset (middlebury, strecha, tum, images, video) as a recording");
  auto args = std::make_shared<ImportArgs>();
  cmd->add_option("kind", args->kind, "middlebury | strecha | tum | images | video")
      ->required()
      ->check(CLI::IsMember(recordings::ImporterKinds()));
  cmd->add_option("source", args->source, "Dataset folder (video: the video file)")->required();
  cmd->add_option("--out", args->out, "Recording folder to create")->required();
  cmd->add_option("--camera", args->camera,
                  "camera.yaml with the intrinsics (for tum unless the folder has one; images and video without it "
                  "get an estimated camera that `arview map` refines)");
  cmd->add_option("--fov", args->fov,
                  "images and video without --camera: the camera's horizontal field of view in degrees (else the "
                  "focal length from the photos' EXIF, else a guess of 0.6 x the diagonal)");
  cmd->add_flag("--force", args->force, "Replace a recording already in --out (never a folder that is not a recording)");
  cmd->callback([args] { RunImport(*args); });
}

}  // namespace arview::app
