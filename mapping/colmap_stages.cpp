// How `arview map` runs a COLMAP stage, apart from the build's sequence (MapBuild,
// mapping/colmap_pipeline.cpp): the stage records that let a re-run skip a stage, COLMAP as a
// child process with its progress parsed, COLMAP's command lines, the frames COLMAP gets (the
// select stage) and the largest model it built. Declared in mapping/map_build_stages.h, and in
// mapping/colmap_stages.h what `arview map extend` runs as well.

#include "mapping/map_build_stages.h"

#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "base/atomic_file.h"
#include "base/image_file.h"
#include "base/process.h"
#include "mapping/colmap_model.h"
#include "mapping/self_calibration.h"

namespace arview::mapping {

namespace fs = std::filesystem;

bool StageRecord::Matches(const std::string& stage, const std::string& inputs) const {
  std::ifstream in(dir_ / (stage + ".inputs"));
  if (!in) return false;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str() == inputs;
}

void StageRecord::Forget(const std::string& stage) const {
  std::error_code ec;
  fs::remove(dir_ / (stage + ".inputs"), ec);
}

void StageRecord::Save(const std::string& stage, const std::string& inputs) const {
  fs::create_directories(dir_);
  WriteFileAtomically(dir_ / (stage + ".inputs"), inputs);
}

std::string FileIdentity(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw map::MapError(file.string() + ": missing or unreadable");
  const auto mtime = fs::last_write_time(file, ec).time_since_epoch().count();
  return std::to_string(size) + " " + std::to_string(mtime);
}

std::string FormatParams(const std::vector<double>& v, const char* separator) {
  std::ostringstream ss;
  ss.precision(17);
  for (size_t i = 0; i < v.size(); ++i) ss << (i ? separator : "") << v[i];
  return ss.str();
}

namespace {

// Hands COLMAP's progress lines to the callback for the stage being run.
class ProgressParser {
 public:
  ProgressParser(std::string stage, int total, const MapBuildCallbacks& cb)
      : stage_(std::move(stage)), total_(total), cb_(cb) {}
  void operator()(const std::string& line) {
    if (!cb_.progress) return;
    if (const auto p = ParseColmapProgress(line, total_)) cb_.progress(stage_, p->first, p->second);
  }

 private:
  std::string stage_;
  int total_;
  const MapBuildCallbacks& cb_;
};

}  // namespace

ColmapRunner::ColmapRunner(const MapBuildOptions& options, const fs::path& out_dir, const MapBuildCallbacks& cb)
    : options_(options), log_(out_dir / "colmap.log"), cb_(cb) {
  if (FindExecutable(options.colmap).empty()) {
    throw map::MapError("COLMAP not found: '" + options.colmap + "' is not " +
                   (options.colmap.find('/') == std::string::npos ? "on PATH" : "an executable file") +
                   " (install COLMAP: apt-get install colmap)");
  }
}

void ColmapRunner::Run(const std::string& stage, const std::vector<std::string>& args, int total) {
  ProgressParser parser(stage, total, cb_);
  Run(stage, args, log_, std::ref(parser));
}

void ColmapRunner::Run(const std::string& stage, const std::vector<std::string>& args, const fs::path& log,
                       const std::function<void(const std::string&)>& on_line) {
  std::vector<std::string> argv{options_.colmap};
  argv.insert(argv.end(), args.begin(), args.end());
  const ProcessResult r = RunProcess(argv, log, on_line, options_.cancel);
  if (!r.ok()) {
    const std::string how = r.signaled ? "was killed by signal " + std::to_string(r.signal)
                                       : "exited with code " + std::to_string(r.exit_code);
    // On a full disk COLMAP's output says only "SQLite error ...: disk I/O error", a dozen
    // times: the cause, found here, is the one line worth printing.
    if (const std::string full = NoRoomToWrite(log_.parent_path()); !full.empty()) {
      throw map::MapError(log_.parent_path().string() + ": no room to write (" + full + "): COLMAP " + args.front() +
                          " (" + stage + " stage) " + how + "; its output is in " + log.string());
    }
    throw ColmapStageError("COLMAP " + args.front() + " (" + stage + " stage) " + how + "; its output is in " +
                               log.string(),
                           stage, log, r.tail);
  }
}

std::vector<int> CandidateFrames(const recordings::Recording& rec, const MapBuildOptions& options) {
  if (!options.frames_spec.empty()) {
    return recordings::ParseFrameSpec(options.frames_spec, static_cast<int>(rec.frames.size()));
  }
  std::vector<int> all(rec.frames.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return all;
}

namespace {

std::string FrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", index);
  return name;
}

}  // namespace

ImageSet PrepareVideoImages(const recordings::Recording& rec, const fs::path& out_dir, const MapBuildOptions& options,
                            const MapBuildCallbacks& cb, StageRecord& stages, std::vector<int>* selected) {
  const std::vector<int> candidates = CandidateFrames(rec, options);
  FrameSelectionOptions sel = options.selection;
  sel.max_frames = options.max_frames;
  const fs::path video = rec.FramePath(0);
  std::ostringstream inputs;
  inputs << "video " << video.string() << " " << FileIdentity(video) << "\nframes " << options.frames_spec
         << "\nblur " << sel.blur_ratio << " " << sel.blur_window << "\nduplicate " << sel.duplicate_threshold
         << "\nmax " << sel.max_frames << "\n";
  ImageSet set;
  set.root = out_dir / "images";
  const fs::path list = out_dir / "selected_frames.txt";
  if (stages.Matches("select", inputs.str()) && fs::exists(list)) {
    std::ifstream in(list);
    int f;
    while (in >> f) selected->push_back(f);
    if (cb.note) cb.note("frame selection: inputs unchanged, reusing " + std::to_string(selected->size()) + " frames");
  } else {
    stages.Forget("select");
    const FrameSelection s = SelectVideoFrames(rec, candidates, sel, [&](int done, int total) {
      options.cancel.ThrowIfCancelled("stopped selecting frames; nothing of this stage kept");
      if (cb.progress) cb.progress("select", done, total);
    });
    *selected = s.frames;
    if (cb.note) {
      cb.note("frame selection: " + std::to_string(s.frames.size()) + " of " + std::to_string(candidates.size()) +
              " frames (" + std::to_string(s.blurred) + " blurred, " + std::to_string(s.duplicates) +
              " near-duplicates, " + std::to_string(s.capped) + " over --max-frames)");
    }
    std::error_code ec;
    fs::remove_all(set.root, ec);
    fs::create_directories(set.root);
    cv::VideoCapture cap(video.string());
    if (!cap.isOpened()) throw recordings::RecordingError(video.string() + ": cannot open the video");
    cv::Mat frame;
    size_t next = 0;
    for (int i = 0; next < selected->size(); ++i) {
      if (!cap.read(frame) || frame.empty()) throw recordings::RecordingError(video.string() + ": ends early");
      if (i != (*selected)[next]) continue;
      options.cancel.ThrowIfCancelled("stopped writing the selected frames; nothing of this stage kept");
      const fs::path png = set.root / FrameName(i);
      WriteImageAtomically(png, frame);
      ++next;
    }
    std::string text;
    for (int f : *selected) text += std::to_string(f) + "\n";
    WriteFileAtomically(list, text);  // on a full disk: one error, and no short list the next run would reuse
    stages.Save("select", inputs.str());
  }
  if (selected->empty()) throw map::MapError(video.string() + ": no usable frames were selected");
  for (int f : *selected) {
    set.names.push_back(FrameName(f));
    set.lookup[set.names.back()] = {f, rec.frames.at(static_cast<size_t>(f)).timestamp};
  }
  return set;
}

ImageSet PrepareStillImages(const recordings::Recording& rec, const MapBuildOptions& options, const MapBuildCallbacks& cb,
                            std::vector<int>* selected) {
  const std::vector<int> candidates = CandidateFrames(rec, options);
  *selected = CapEvenly(candidates, options.max_frames);
  if (selected->size() < candidates.size() && cb.note) {
    cb.note("--max-frames " + std::to_string(options.max_frames) + ": using " + std::to_string(selected->size()) +
            " of " + std::to_string(candidates.size()) + " frames, evenly spread");
  }
  ImageSet set;
  set.root = fs::absolute(rec.root).lexically_normal();
  for (int f : *selected) {
    const auto& entry = rec.frames.at(static_cast<size_t>(f));
    set.names.push_back(fs::path(entry.path).lexically_normal().generic_string());
    set.lookup[set.names.back()] = {f, entry.timestamp};
  }
  return set;
}

namespace {

std::vector<double> ColmapCameraParams(const calib::Camera& c, bool* full_opencv) {
  // COLMAP's pixel centres are at +0.5 (docs/architecture.md, "Pixel coordinates").
  std::vector<double> p{c.fx, c.fy, c.cx + 0.5, c.cy + 0.5, c.dist[0], c.dist[1], c.dist[2], c.dist[3]};
  *full_opencv = c.dist[4] != 0.0;
  if (*full_opencv) p.insert(p.end(), {c.dist[4], 0.0, 0.0, 0.0});
  return p;
}

}  // namespace

fs::path LargestModel(const fs::path& sparse_root, int* count, const MapBuildCallbacks& cb) {
  fs::path best;
  std::uint64_t best_images = 0;
  std::vector<std::pair<std::string, std::uint64_t>> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(sparse_root, ec)) {
    if (!entry.is_directory() || !fs::exists(entry.path() / "images.bin")) continue;
    const std::uint64_t n = CountRegisteredImages(entry.path());
    found.push_back({entry.path().filename().string(), n});
    if (n > best_images || (n == best_images && entry.path() < best)) {
      best_images = n;
      best = entry.path();
    }
  }
  *count = static_cast<int>(found.size());
  if (found.size() > 1 && cb.note) {
    std::string list;
    for (const auto& [name, n] : found) list += (list.empty() ? "" : ", ") + name + ": " + std::to_string(n);
    cb.note("COLMAP built " + std::to_string(found.size()) + " separate models (registered images " + list +
            "); keeping the largest, " + best.filename().string());
  }
  return best;
}

bool FramesDoubled(const calib::Camera& camera, const MapBuildOptions& options) {
  return options.double_frames_below_px <= 0 || std::max(camera.width, camera.height) < options.double_frames_below_px;
}

std::vector<std::string> MatchArgs(const MapBuildOptions& options, const fs::path& database, int frames) {
  const bool exhaustive = ExhaustiveMatchingWanted(options, frames);
  std::vector<std::string> args{exhaustive ? "exhaustive_matcher" : "sequential_matcher",
                                "--database_path", database.string(),
                                "--SiftMatching.use_gpu", "0",
                                "--SiftMatching.num_threads", std::to_string(options.threads)};
  if (exhaustive) {
    // Four blocks a side (COLMAP's default is one block of 50 images): the same pairs, matched in
    // 16 steps that each print "Matching block [a/A, b/B]", so that the longest stage shows
    // progress and a time left.
    args.insert(args.end(), {"--ExhaustiveMatching.block_size", std::to_string(std::max(2, (frames + 3) / 4))});
  } else {
    args.insert(args.end(), {"--SequentialMatching.overlap", std::to_string(options.sequential_overlap),
                             "--SequentialMatching.quadratic_overlap", options.quadratic_overlap ? "1" : "0"});
  }
  return args;
}

// COLMAP's command lines for the three stages. Each stage's inputs include the previous
// stage's, so that a change re-runs everything after it.
std::vector<std::string> ColmapExtractArgs(const calib::Camera& camera, const MapBuildOptions& options,
                                           const fs::path& database, const fs::path& image_root,
                                           const fs::path& image_list) {
  bool full_opencv = false;
  const std::vector<double> params = camera.calibrated ? ColmapCameraParams(camera, &full_opencv) : ColmapRadialParams(camera);
  const char* model = !camera.calibrated ? "RADIAL" : full_opencv ? "FULL_OPENCV" : "OPENCV";
  return {"feature_extractor", "--database_path", database.string(), "--image_path", image_root.string(),
          "--image_list_path", image_list.string(), "--ImageReader.camera_model", model,
          "--ImageReader.single_camera", "1", "--ImageReader.camera_params", FormatParams(params),
          "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", std::to_string(options.threads),
          "--SiftExtraction.max_num_features", std::to_string(options.max_num_features),
          "--SiftExtraction.max_num_orientations", std::to_string(options.max_num_orientations),
          "--SiftExtraction.first_octave", FramesDoubled(camera, options) ? "-1" : "0"};
}

std::vector<std::string> ColmapMapperArgs(const MapBuildOptions& options, const fs::path& database,
                                          const fs::path& image_root, const fs::path& sparse, bool self_calibrate) {
  // Self-calibration refines the focal length, the principal point and the radial terms: held at
  // the image's centre, phone-fox's principal point (15 px off it) turned every pose by 0.6° and
  // the keyframes were 4.6 x further from the ground truth; refined, within 1.06 x of the
  // calibrated map's (docs/mapping.md, "Maps without a calibration").
  const std::string refine = options.refine_intrinsics || self_calibrate ? "1" : "0";
  std::vector<std::string> args{"mapper", "--database_path", database.string(), "--image_path",
                                image_root.string(), "--output_path", sparse.string(),
                                "--Mapper.num_threads", std::to_string(options.threads),
                                // COLMAP runs a bundle adjustment of fewer residuals on one thread;
                                // its default bar (50,000) keeps every local adjustment of a
                                // 96-frame room (20,000-45,000) there: 27 s of its 66 s mapper.
                                // The demo room's mapper at 5,000: 46 s, the same map.
                                "--Mapper.ba_min_num_residuals_for_multi_threading", "5000",
                                "--Mapper.ba_refine_focal_length", refine,
                                "--Mapper.ba_refine_principal_point", refine,
                                "--Mapper.ba_refine_extra_params", refine,
                                "--Mapper.ba_global_images_ratio", FormatParams({options.ba_global_ratio}),
                                "--Mapper.ba_global_points_ratio", FormatParams({options.ba_global_ratio}),
                                "--Mapper.ba_global_max_num_iterations",
                                std::to_string(options.ba_global_max_iterations),
                                "--Mapper.ba_local_max_num_iterations",
                                std::to_string(options.ba_local_max_iterations)};
  args.insert(args.end(), options.extra_mapper_args.begin(), options.extra_mapper_args.end());
  return args;
}

bool ExhaustiveMatchingWanted(const MapBuildOptions& options, int frames) {
  return options.matcher == MatcherKind::kExhaustive ||
         (options.matcher == MatcherKind::kAuto && frames <= options.auto_exhaustive_limit);
}

std::optional<std::pair<int, int>> ParseColmapProgress(const std::string& line, int total_images) {
  // sscanf rather than std::regex: no allocation per line, and no GCC 12 false warnings.
  const char* text = line.c_str();
  int a = 0, na = 0, b = 0, nb = 0;
  if (std::sscanf(text, "Processed file [%d/%d]", &a, &na) == 2 ||
      std::sscanf(text, "Matching image [%d/%d]", &a, &na) == 2) {
    return std::make_pair(a, na);
  }
  if (std::sscanf(text, "Matching block [%d/%d, %d/%d]", &a, &na, &b, &nb) == 4) {
    return std::make_pair((a - 1) * nb + b, na * nb);
  }
  if (std::sscanf(text, "Matching block [%d/%d]", &a, &na) == 2) return std::make_pair(a, na);  // listed pairs
  if (std::sscanf(text, "Registering image #%d (%d)", &b, &a) == 2) return std::make_pair(a, total_images);
  if (line.rfind("Initializing with image pair", 0) == 0) return std::make_pair(0, total_images);
  return std::nullopt;
}

// The stages `arview map extend` shares with `arview map` (mapping/colmap_stages.h).

ImageSet SelectImages(const recordings::Recording& recording, const fs::path& out_dir, const MapBuildOptions& options,
                      const MapBuildCallbacks& cb, std::vector<int>* selected) {
  CandidateFrames(recording, options);  // a bad --frames fails before anything is written
  StageRecord stages(out_dir);
  return recording.IsVideo() ? PrepareVideoImages(recording, out_dir, options, cb, stages, selected)
                             : PrepareStillImages(recording, options, cb, selected);
}

void RunColmap(const MapBuildOptions& options, const fs::path& out_dir, const std::string& stage,
               const std::vector<std::string>& args, int total, const MapBuildCallbacks& cb) {
  ColmapRunner(options, out_dir, cb).Run(stage, args, total);
}

fs::path LargestColmapModel(const fs::path& sparse_root) {
  int models = 0;
  return LargestModel(sparse_root, &models, {});
}

}  // namespace arview::mapping
