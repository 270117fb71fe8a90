#pragma once
// Importers: public datasets and plain image folders / videos turned into recording folders
// (docs/architecture.md, "The recording folder"). Still-image datasets get timestamp = frame
// index in seconds and frames in name order; ground truth becomes groundtruth.txt (TUM,
// camera-to-world). Malformed input throws RecordingError naming the file (and line).
//
// Every importer writes frames.txt last, so that an import that fails half-way never leaves a
// folder that LoadRecording accepts.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "recordings/trajectory.h"

namespace arview::recordings {

struct ImportOptions {
  // Replace an existing recording in the output folder. A non-empty folder that is not a
  // recording (no frames.txt) is never touched.
  bool overwrite = false;
  // Intrinsics for sources that carry none (images, video, tum); optional for the others.
  std::optional<calib::Camera> camera;
  // images and video without `camera`: the horizontal field of view in degrees (`--fov`), else
  // the focal length from the first image's EXIF, else a guess (calib::GuessedFocal: 0.6 x the diagonal). The
  // recording's camera is then marked uncalibrated (`calibrated: 0`) and `arview map` refines it.
  std::optional<double> horizontal_fov_deg;
};

struct ImportResult {
  int frame_count = 0;
  bool has_groundtruth = false;
  calib::Camera camera;
  std::vector<std::string> notes;  // what the importer decided on the user's behalf
};

// Middlebury multi-view stereo layout: a folder with one `*_par.txt` whose first line is the
// image count and every further line `name k11..k33 r11..r33 t1 t2 t3`, P = K[R|t].
// A recording has one camera, so every image must share K (else RecordingError naming the
// first line that differs); K must have zero skew. R is re-orthonormalised (the files carry
// ~1e-9 rounding); a matrix farther than 1e-4 from a rotation is an error.
ImportResult ImportMiddlebury(const std::filesystem::path& source_dir, const std::filesystem::path& out_dir,
                              const ImportOptions& options = {});

// EPFL (Strecha) multi-view benchmark: `images/` and `gt_dense_cameras/<image name>.camera`:
// K (3 lines), 3 distortion values, R camera-to-world (3 lines), centre C, `width height`.
// P = K[Rᵀ | −RᵀC]. Non-zero distortion values are rejected (their model is undocumented).
ImportResult ImportStrecha(const std::filesystem::path& source_dir, const std::filesystem::path& out_dir,
                           const ImportOptions& options = {});

// TUM RGB-D layout: rgb.txt ("timestamp rgb/file.png") and groundtruth.txt (TUM). Frames keep
// their timestamps; groundtruth.txt is validated and copied. Needs options.camera (TUM folders
// carry no intrinsics) unless the source holds a camera.yaml.
ImportResult ImportTum(const std::filesystem::path& source_dir, const std::filesystem::path& out_dir,
                       const ImportOptions& options = {});

// A folder of images (png, jpg, jpeg, bmp, tif, tiff, ppm, pgm) in name order; every image the
// size of options.camera, or without it of the first image (an estimated camera, above).
ImportResult ImportImages(const std::filesystem::path& source_dir, const std::filesystem::path& out_dir,
                          const ImportOptions& options = {});

// One video file, copied into frames/ and decoded once (OpenCV FFmpeg backend) to count its
// frames and read their timestamps; options.camera's size must match the video (without it, an
// estimated camera from --fov or a guess: a video's container carries no focal length).
ImportResult ImportVideo(const std::filesystem::path& video_file, const std::filesystem::path& out_dir,
                         const ImportOptions& options = {});

// The importer kinds `arview import` accepts, and dispatch by name (RecordingError if unknown).
const std::vector<std::string>& ImporterKinds();
ImportResult Import(const std::string& kind, const std::filesystem::path& source,
                    const std::filesystem::path& out_dir, const ImportOptions& options = {});

}  // namespace arview::recordings
