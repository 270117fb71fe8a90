// arview import <kind> <source> --out <recording> [--camera camera.yaml] [--force]

#include <iostream>

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
  bool force = false;
};

void RunImport(const ImportArgs& args) {
  recordings::ImportOptions options;
  options.overwrite = args.force;
  if (!args.camera.empty()) {
    options.camera = calib::LoadCamera(args.camera);
  }
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
                  "camera.yaml with the intrinsics (required for images and video; for tum unless the folder has one)");
  cmd->add_flag("--force", args->force, "Replace a recording already in --out (never a folder that is not a recording)");
  cmd->callback([args] { RunImport(*args); });
}

}  // namespace arview::app
