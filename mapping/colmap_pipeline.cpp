#include "mapping/colmap_pipeline.h"

#include "base/atomic_file.h"
#include "base/image_file.h"


#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>
#include <fstream>
#include <cstdio>
#include <sstream>

#include "base/process.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_stages.h"
#include "mapping/fold_retries.h"
#include "mapping/gap_retry.h"
#include "mapping/job_stages.h"
#include "mapping/leaf_mapping.h"
#include "mapping/self_calibration.h"
#include "mapping/map_extend.h"
#include "mapping/pair_matching.h"
#include "recordings/trajectory.h"

namespace arview::mapping {

namespace fs = std::filesystem;

MatcherKind ParseMatcherKind(const std::string& text) {
  return ParseEnum<MatcherKind, map::MapError>(text, "--matcher");
}

MatchEngine ParseMatchEngine(const std::string& text) {
  return ParseEnum<MatchEngine, map::MapError>(text, "--match-engine");
}

namespace {

// Stage inputs as text: a stage is skipped when the text saved after its last success matches.
class StageRecord {
 public:
  explicit StageRecord(const fs::path& out_dir) : dir_(out_dir / "stages") {}
  bool Matches(const std::string& stage, const std::string& inputs) const {
    std::ifstream in(dir_ / (stage + ".inputs"));
    if (!in) return false;
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str() == inputs;
  }
  void Forget(const std::string& stage) const {
    std::error_code ec;
    fs::remove(dir_ / (stage + ".inputs"), ec);
  }
  void Save(const std::string& stage, const std::string& inputs) const {
    fs::create_directories(dir_);
    WriteFileAtomically(dir_ / (stage + ".inputs"), inputs);
  }

 private:
  fs::path dir_;
};

std::string FileIdentity(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw map::MapError(file.string() + ": missing or unreadable");
  const auto mtime = fs::last_write_time(file, ec).time_since_epoch().count();
  return std::to_string(size) + " " + std::to_string(mtime);
}

std::string Joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += a + "\n";
  return s;
}

std::string FormatParams(const std::vector<double>& v, const char* separator = ",") {
  std::ostringstream ss;
  ss.precision(17);
  for (size_t i = 0; i < v.size(); ++i) ss << (i ? separator : "") << v[i];
  return ss.str();
}

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

class ColmapRunner {
 public:
  ColmapRunner(const MapBuildOptions& options, const fs::path& out_dir, const MapBuildCallbacks& cb)
      : options_(options), log_(out_dir / "colmap.log"), cb_(cb) {
    if (FindExecutable(options.colmap).empty()) {
      throw map::MapError("COLMAP not found: '" + options.colmap + "' is not " +
                     (options.colmap.find('/') == std::string::npos ? "on PATH" : "an executable file") +
                     " (install COLMAP: apt-get install colmap)");
    }
  }

  void Run(const std::string& stage, const std::vector<std::string>& args, int total) {
    ProgressParser parser(stage, total, cb_);
    Run(stage, args, log_, std::ref(parser));
  }
  // The same with its own log file and line handler (several at once: the verifying processes).
  void Run(const std::string& stage, const std::vector<std::string>& args, const fs::path& log,
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
  const fs::path& log() const { return log_; }

 private:
  const MapBuildOptions& options_;
  fs::path log_;
  const MapBuildCallbacks& cb_;
};

std::vector<int> CandidateFrames(const recordings::Recording& rec, const MapBuildOptions& options) {
  if (!options.frames_spec.empty()) {
    return recordings::ParseFrameSpec(options.frames_spec, static_cast<int>(rec.frames.size()));
  }
  std::vector<int> all(rec.frames.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return all;
}

std::string FrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", index);
  return name;
}

// Video: the selected frames written as PNG files under <out>/images (skipped when done before
// with the same selection).
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

std::vector<double> ColmapCameraParams(const calib::Camera& c, bool* full_opencv) {
  // COLMAP's pixel centres are at +0.5 (docs/architecture.md, "Pixel coordinates").
  std::vector<double> p{c.fx, c.fy, c.cx + 0.5, c.cy + 0.5, c.dist[0], c.dist[1], c.dist[2], c.dist[3]};
  *full_opencv = c.dist[4] != 0.0;
  if (*full_opencv) p.insert(p.end(), {c.dist[4], 0.0, 0.0, 0.0});
  return p;
}

void ClearMatches(const fs::path& database) {
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite)
      .Execute("DELETE FROM matches; DELETE FROM two_view_geometries;", "clear old matches");
}

// The sparse model with the most registered images among <out>/sparse/<n>/.
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

// "interrupted (SIGINT) during COLMAP's match stage; kept the finished stages (select,
// extract): re-run the same command to continue"
std::string InterruptedStageMessage(const CancellationToken& cancel, const std::string& stage,
                                    const std::vector<StageTiming>& finished) {
  std::string kept;
  for (const auto& t : finished) kept += (kept.empty() ? "" : ", ") + t.stage;
  return "interrupted (" + SignalName(cancel.Signal()) + ") during COLMAP's " + stage + " stage; " +
         (kept.empty() ? std::string("no stage was finished")
                       : "kept the finished stages (" + kept + "): re-run the same command to continue");
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
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

// arview's matching (mapping/pair_matching.h) needs image names COLMAP's match list can hold:
// matches_importer splits a pair's line at the first space.
bool NamesFitAMatchList(const std::vector<std::string>& names) {
  return std::none_of(names.begin(), names.end(), [](const std::string& name) {
    return name.empty() || name.find_first_of(" \t\r\n") != std::string::npos;
  });
}

std::vector<ImagePair> PairsToMatch(const MapBuildOptions& options, int frames) {
  return ExhaustiveMatchingWanted(options, frames)
             ? ExhaustivePairs(frames)
             : SequentialPairs(frames, options.sequential_overlap, options.quadratic_overlap);
}

int VerifyingProcesses(const MapBuildOptions& options) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, options.threads <= 0 ? cores : options.threads);
}

// "exhaustive" or "sequential 10 quadratic": which pairs are matched, for the stage records.
std::string PairsWanted(const MapBuildOptions& options, int frames) {
  return ExhaustiveMatchingWanted(options, frames)
             ? "exhaustive"
             : "sequential " + std::to_string(options.sequential_overlap) + (options.quadratic_overlap ? " quadratic" : "");
}

// What decides arview's matches, for the stage record.
std::string ArviewMatchInputs(const MapBuildOptions& options, int frames) {
  const PairMatchingOptions& m = options.pair_matching;
  std::ostringstream ss;
  ss << "arview pair matching\n" << PairsWanted(options, frames) << "\nratio " << m.max_ratio << " distance " << m.max_distance << " cross " << m.cross_check << " trees "
     << m.trees << " checks " << m.checks << " at least " << m.min_matches << "\nmatches_importer raw\n";
  return ss.str();
}

// What decides the matches of the Slurm jobs (matches_importer on pairs), for the stage record.
std::string SlurmMatchInputs(const MapBuildOptions& options, int frames) {
  return "COLMAP pair matching in Slurm jobs\n" + PairsWanted(options, frames) + "\nthreads " +
         std::to_string(options.threads) + "\n";
}

// The candidate matches in `lists` verified by COLMAP (matches_importer --match_type raw), one
// process per list: the first in `database` itself, the others in copies of it whose verified
// pairs are then added to it. COLMAP verifies raw matches one pair after another on one core.
void VerifyMatches(ColmapRunner& colmap, const fs::path& database, const std::vector<fs::path>& lists,
                   int pairs_listed, const MapBuildCallbacks& cb) {
  std::vector<fs::path> databases{database};
  for (size_t k = 1; k < lists.size(); ++k) {
    databases.push_back(database.string() + ".verify-" + std::to_string(k));
    CopyColmapDatabase(database, databases.back());
  }
  const auto remove_copies = [&] {
    for (size_t k = 1; k < databases.size(); ++k) RemoveColmapDatabase(databases[k]);
  };
  std::mutex mutex;
  int verified = 0;
  // matches_importer prints each pair as "<name1> - <name2>" when it starts on it.
  const auto on_line = [&](const std::string& line) {
    if (line.find(" - ") == std::string::npos || !cb.progress) return;
    const std::lock_guard lock(mutex);
    verified = std::min(verified + 1, pairs_listed);
    cb.progress("verify", verified, pairs_listed);
  };
  std::vector<std::exception_ptr> failures(lists.size());
  std::vector<fs::path> logs(lists.size());
  std::vector<std::thread> workers;
  for (size_t k = 0; k < lists.size(); ++k) {
    logs[k] = colmap.log().string() + ".verify-" + std::to_string(k);
    std::error_code ec;
    fs::remove(logs[k], ec);
    workers.emplace_back([&, k] {
      try {
        colmap.Run("verify",
                   {"matches_importer", "--database_path", databases[k].string(), "--match_list_path", lists[k].string(),
                    "--match_type", "raw", "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads", "1"},
                   logs[k], on_line);
      } catch (...) {
        failures[k] = std::current_exception();
      }
    });
  }
  for (auto& w : workers) w.join();
  // The processes' output into colmap.log, one after another, as if they had run in turn.
  {
    std::ofstream log(colmap.log(), std::ios::app);
    for (const fs::path& l : logs) {
      std::ifstream in(l);
      log << in.rdbuf();
      std::error_code ec;
      fs::remove(l, ec);
    }
  }
  for (const auto& f : failures) {
    if (!f) continue;
    remove_copies();
    std::rethrow_exception(f);
  }
  try {
    for (size_t k = 1; k < databases.size(); ++k) MergeVerifiedPairs(database, databases[k]);
  } catch (...) {
    remove_copies();
    throw;
  }
  remove_copies();
}

// arview's matching: the pairs matched with a kd-tree per frame, then verified by COLMAP.
// `timings` gets the two steps.
void MatchWithArview(ColmapRunner& colmap, const fs::path& database, const fs::path& out_dir,
                     const std::vector<std::string>& names, const MapBuildOptions& options, const MapBuildCallbacks& cb,
                     std::vector<StageTiming>* timings) {
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<cv::Mat> descriptors = ReadImageDescriptors(database, names, options.cancel);
  const std::vector<ImagePair> pairs = PairsToMatch(options, static_cast<int>(names.size()));
  PairMatchingOptions matching = options.pair_matching;
  matching.threads = options.threads;
  const std::vector<PairMatches> matches = MatchImagePairs(
      descriptors, pairs, matching,
      [&](int done, int total) {
        if (cb.progress) cb.progress("match", done, total);
      },
      options.cancel);
  const int processes = VerifyingProcesses(options);
  std::vector<fs::path> lists;
  for (int k = 0; k < processes; ++k) lists.push_back(out_dir / ("matches-" + std::to_string(k) + ".txt"));
  WriteMatchLists(names, matches, lists);
  timings->push_back({"match", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), false});
  t0 = std::chrono::steady_clock::now();
  const int listed = static_cast<int>(
      std::count_if(matches.begin(), matches.end(), [](const PairMatches& m) { return !m.matches.empty(); }));
  const auto remove_lists = [&] {
    std::error_code ec;
    for (const fs::path& l : lists) fs::remove(l, ec);
  };
  try {
    VerifyMatches(colmap, database, lists, listed, cb);
  } catch (...) {
    remove_lists();
    throw;
  }
  remove_lists();
  timings->push_back({"verify", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), false});
}

// A COLMAP model that arview moved into a metric frame says so in <model>/arview_frame.txt: the
// request it was made from and the frame record. A re-run of `arview map` whose COLMAP stages
// are all skipped reads that model again: with the same request it is taken as it is (the map
// file comes out byte-identical), with another one the new fit starts from it.
constexpr const char* kModelFrameFile = "arview_frame.txt";

std::string RequestSignature(const ScaleRequest& r) {
  switch (r.from) {
    case ScaleFrom::kNone: return "none";
    case ScaleFrom::kCameraHeight: return "camera-height";
    case ScaleFrom::kKnownDistance: return "known-distance";
    case ScaleFrom::kBoard: {
      char text[96];
      std::snprintf(text, sizeof text, "board %dx%d %.17g %s", r.board.inner_corners.width, r.board.inner_corners.height,
                    r.board.square, r.board.on_floor ? "floor" : "off-floor");
      return text;
    }
  }
  return "none";
}

void WriteModelFrame(const fs::path& model_dir, const std::string& signature, const map::MapFrame& f) {
  std::ostringstream text;
  text.precision(17);
  text << "arview map frame 1\nrequest " << signature << "\nsource " << static_cast<int>(f.scale_source) << " "
       << (f.z_up ? 1 : 0) << " " << f.scale_error << "\nfrom_colmap " << f.from_colmap.scale;
  for (int i = 0; i < 9; ++i) text << " " << f.from_colmap.R(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) text << " " << f.from_colmap.t[i];
  text << "\nhow " << f.how << "\n";
  WriteFileAtomically(model_dir / kModelFrameFile, text.str());
}

struct ModelFrame {
  std::string signature;
  map::MapFrame frame;
};

// Nothing when the model has no record (COLMAP's own frame) or an unreadable one.
std::optional<ModelFrame> ReadModelFrame(const fs::path& model_dir) {
  std::ifstream in(model_dir / kModelFrameFile);
  std::string line;
  if (!in || !std::getline(in, line) || line != "arview map frame 1") return std::nullopt;
  ModelFrame m;
  int source = 0, z_up = 0;
  std::string key;
  if (!std::getline(in, line) || line.rfind("request ", 0) != 0) return std::nullopt;
  m.signature = line.substr(8);
  if (!(in >> key >> source >> z_up >> m.frame.scale_error) || key != "source" || source < 0 || source > 3)
    return std::nullopt;
  m.frame.scale_source = static_cast<map::ScaleSource>(source);
  m.frame.z_up = z_up == 1;
  if (!(in >> key >> m.frame.from_colmap.scale) || key != "from_colmap") return std::nullopt;
  for (int i = 0; i < 9; ++i) in >> m.frame.from_colmap.R(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) in >> m.frame.from_colmap.t[i];
  in >> std::ws;
  if (!in || !std::getline(in, line) || line.rfind("how ", 0) != 0) return std::nullopt;
  m.frame.how = line.substr(4);
  return m;
}

// The COLMAP model in <model_dir> moved into the metric frame: written beside it
// (colmap_model.h's WriteTransformedModel, with its frame record), then put in its place, so that
// a failed write leaves the model as it was.
void TransformColmapModel(const fs::path& model_dir, const Sim3& transform, const std::string& signature,
                          const map::MapFrame& frame) {
  const fs::path staged = model_dir.string() + ".metric", old = model_dir.string() + ".old";
  std::error_code ec;
  fs::remove_all(staged, ec);
  fs::remove_all(old, ec);
  try {
    WriteTransformedModel(model_dir, staged, transform);
    WriteModelFrame(staged, signature, frame);
  } catch (...) {
    fs::remove_all(staged, ec);
    throw;
  }
  fs::rename(model_dir, old);
  fs::rename(staged, model_dir);
  fs::remove_all(old, ec);
}

// check.json's two distances follow the map into metres.
void ScaleCheckDistances(double scale, MapCheck* check) {
  check->path_extent *= scale;
  check->scene_depth *= scale;
}

// A frame's grey image, or an empty one when the file cannot be read (the board is then not
// seen in it).
cv::Mat GreyImageOrNone(const fs::path& file) {
  try {
    return ReadImageFile(file, cv::IMREAD_GRAYSCALE);
  } catch (const Error&) {
    return cv::Mat();
  }
}

// A keyframe's grey image from the folder the map's frames were given to COLMAP from.
KeyframeImages KeyframeImagesIn(const map::Map& map, const std::vector<fs::path>& roots) {
  return [&map, roots](std::size_t k) {
    for (const fs::path& root : roots) {
      const fs::path file = root / map.keyframes[k].name;
      std::error_code ec;
      if (fs::is_regular_file(file, ec)) return GreyImageOrNone(file);
    }
    return cv::Mat();
  };
}

// The requested fit. Throws MapError when it cannot be made.
// `board_search`: the board's search already under way, or null to search the keyframes now.
MetricFit FitRequested(const map::Map& map, const ScaleRequest& request, const KeyframeImages& images,
                       const MapBuildOptions& options, const MapBuildCallbacks& cb,
                       BoardSearchInBackground* board_search = nullptr) {
  switch (request.from) {
    case ScaleFrom::kBoard: {
      const auto progress = [&](int done, int total) {
        if (cb.progress) cb.progress("board", done, total);
      };
      const std::vector<BoardSighting> seen =
          board_search ? board_search->Sightings(map, progress, options.cancel)
                       : FindBoard(map, images, request.board.inner_corners, progress, options.cancel);
      return FitFromBoard(map, TriangulateBoard(map, seen, request.board.inner_corners), request.board);
    }
    case ScaleFrom::kKnownDistance: {
      // One end, then the other: an error is about the first end given wrongly.
      const TriangulatedPoint a = TriangulatePoint(map, request.point_a);
      const TriangulatedPoint b = TriangulatePoint(map, request.point_b);
      return FitFromDistance(map, a, b, request.distance_m);
    }
    case ScaleFrom::kCameraHeight:
      return FitFromCameraHeight(map);
    case ScaleFrom::kNone:
      break;
  }
  throw map::MapError("no scale source requested");
}

// The built map made metric as options.scale asks (a board that fails: the estimate, and
// result->scale_failure says why), the COLMAP model with it.
// `read_model` reads the moved model back: the map is then exactly what a re-run reads (COLMAP
// rounds the transformed poses its own way), so that the same command again writes the same bytes.
void MakeMetric(const KeyframeImages& images, BoardSearchInBackground* board_search, const MapBuildOptions& options,
                const MapBuildCallbacks& cb, const std::function<map::Map()>& read_model, MapBuildResult* result) {
  // The model read may be one an earlier run moved already: its frame comes with it.
  const std::optional<ModelFrame> earlier = ReadModelFrame(result->model_dir);
  if (earlier) {
    result->map.frame = earlier->frame;
    ScaleRequest asked = options.scale;
    if (earlier->signature == RequestSignature(asked) && asked.from == ScaleFrom::kBoard &&
        earlier->frame.scale_source != map::ScaleSource::kBoard) {
      result->scale_failure = "the board could not be used when this model was made (the output of that run of "
                              "arview map says why)";
    }
    if (earlier->signature == RequestSignature(asked) || asked.from == ScaleFrom::kNone) return;
  }
  if (options.scale.from == ScaleFrom::kNone) return;
  std::optional<MetricFit> fit;
  try {
    fit = FitRequested(result->map, options.scale, images, options, cb, board_search);
  } catch (const map::MapError& e) {
    if (options.scale.from == ScaleFrom::kCameraHeight) {
      if (cb.note) cb.note(std::string("the map stays in COLMAP's units and orientation: ") + e.what());
      return;
    }
    result->scale_failure = e.what();
    ScaleRequest estimate;
    estimate.from = ScaleFrom::kCameraHeight;
    try {
      fit = FitRequested(result->map, estimate, images, options, cb);
    } catch (const map::MapError&) {
      return;
    }
  }
  options.cancel.ThrowIfCancelled("COLMAP's stages are finished and kept; the map file was not written");
  ApplyMetricFit(*fit, &result->map);
  // What is asked is recorded, also when a board fell back to the estimate: the same command
  // again then takes the model as it is rather than failing on the board a second time.
  TransformColmapModel(result->model_dir, fit->to_metric, RequestSignature(options.scale), result->map.frame);
  const map::MapFrame frame = result->map.frame;
  result->map = read_model();
  result->map.frame = frame;
  ScaleCheckDistances(fit->to_metric.scale, &result->check);
}

}  // namespace

// Stages `arview map extend` runs as well (declared in mapping/colmap_stages.h), used above too.

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

// check.json, the keyframes, the top view, and the map file last: a disk that fills at an
// earlier file fails the command without a new map.arvmap beside the error (each file is
// written atomically; a previous map stays whole).
void WriteMapFiles(const MapBuildResult& result, const fs::path& out_dir, const MapBuildOptions& options,
                   const MapBuildCallbacks& cb) {
  WriteMapCheck(result.check, out_dir / kMapCheckFileName);
  if (cb.warning)
    for (const std::string& w : result.check.warnings) cb.warning(w);
  RequireModelValuesInRange(result.map, result.model_dir);
  options.cancel.ThrowIfCancelled("COLMAP's stages are finished and kept; the map file was not written");
  WriteKeyframesTum(result.map, out_dir / "keyframes.txt");
  WriteTopView(result.map, out_dir / "map.png");
  map::SaveMap(result.map, out_dir / map::kMapFileName);
}

MapCheck RecheckMap(const fs::path& map_dir) {
  const map::Map built = map::LoadMap(map_dir);
  const fs::path database = map_dir / "database.db";
  int models = 0;
  const fs::path model_dir = LargestModel(map_dir / "sparse", &models, {});
  if (model_dir.empty())
    throw map::MapError((map_dir / "sparse").string() + ": no COLMAP model to check (the folder arview map wrote keeps it)");
  FrameLookup frames;
  for (const map::Keyframe& k : built.keyframes) frames[k.name] = {k.frame_index, k.timestamp};
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  const map::Map model = ReadColmapMap(model_dir, database, frames, {}, &keypoints, false);
  MapCheck check = CheckMap(model, keypoints, ReadTwoViewGeometries(database, model));
  // A map made without a calibration keeps the warning on its refined intrinsics.
  std::error_code ec;
  if (fs::exists(map_dir / "camera.yaml", ec) && !calib::LoadCamera(map_dir / "camera.yaml").calibrated) {
    for (const std::string& problem : ImplausibleIntrinsics(built.camera)) check.warnings.push_back(problem);
  }
  WriteMapCheck(check, map_dir / kMapCheckFileName);
  return check;
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
  if (std::sscanf(text, "Registering image #%d (%d)", &b, &a) == 2) return std::make_pair(a, total_images);
  if (line.rfind("Initializing with image pair", 0) == 0) return std::make_pair(0, total_images);
  return std::nullopt;
}

namespace {

// One `arview map` run as the sequence of its stages (BuildMap below): each a method, in the
// order they run, over the state they hand on (the frames, the database, each stage's inputs).
// A stage whose recorded inputs match and whose outputs exist is skipped (StageRecord); a stage
// that fails or is interrupted removes what it left half written.
class MapBuild {
 public:
  using StageWork = std::function<void(std::vector<StageTiming>* steps)>;

  MapBuild(const recordings::Recording& recording, const fs::path& out_dir, const MapBuildOptions& options,
           const MapBuildCallbacks& cb)
      : recording_(recording),
        out_dir_(out_dir),
        options_(options),
        cb_(cb),
        stages_(out_dir),
        colmap_(options, out_dir, cb),
        database_(out_dir / "database.db"),
        sparse_(out_dir / "sparse"),
        stages_as_jobs_(options.engine == MapEngine::kSlurm && options.slurm_chunk > 0),
        self_calibrate_(!recording.camera.calibrated),
        start_camera_(recording.camera) {}

  // The frames COLMAP gets, their list, and the extraction's inputs (its command line and each
  // frame's identity).
  void SelectFrames() {
    t0_ = std::chrono::steady_clock::now();
    images_ = recording_.IsVideo()
                  ? PrepareVideoImages(recording_, out_dir_, options_, cb_, stages_, &result_.selected_frames)
                  : PrepareStillImages(recording_, options_, cb_, &result_.selected_frames);
    result_.timings.push_back({"select", Seconds(t0_), false});
    if (images_.names.size() < 2)
      throw map::MapError("a map needs at least 2 frames (got " + std::to_string(images_.names.size()) + ")");
    frames_ = static_cast<int>(images_.names.size());
    const fs::path list = out_dir_ / "image_list.txt";
    std::string names;
    for (const auto& name : images_.names) names += name + "\n";
    WriteFileAtomically(list, names);  // a full disk: "cannot write (<why>)", no empty list left
    extract_args_ = ColmapExtractArgs(recording_.camera, options_, database_, images_.root, list);
    // Each stage's inputs include the previous stage's, so that a change re-runs everything after it.
    inputs_ = Joined(extract_args_);
    for (const auto& name : images_.names) inputs_ += name + " " + FileIdentity(images_.root / name) + "\n";
  }

  // SIFT into the database: COLMAP's feature_extractor, or Slurm jobs (--engine slurm
  // --slurm-chunk N, mapping/job_stages.h; the same database either way, so the stage records do
  // not say where it was made).
  void Extract() {
    const StageWork run = stages_as_jobs_ ? StageWork([this](std::vector<StageTiming>*) {
      ExtractOnSlurm(recording_.camera, options_, JobFiles(), images_.names, cb_);
    })
                                          : ColmapStage("extract", extract_args_);
    const auto remove_database = [this] { RemoveColmapDatabase(database_); };
    RunStage("extract", inputs_, remove_database, run, fs::exists(database_), remove_database);
  }

  // The verified pairs: arview's matcher, COLMAP's, or Slurm jobs.
  void Match() {
    const bool arview_wanted = options_.match_engine == MatchEngine::kArview ||
                               (options_.match_engine == MatchEngine::kAuto && !FramesDoubled(recording_.camera, options_));
    const bool arview_matches = !stages_as_jobs_ && arview_wanted && NamesFitAMatchList(images_.names);
    if (arview_wanted && !arview_matches && cb_.note)
      cb_.note("a frame's file name holds a space: COLMAP matches the frames itself (--match-engine colmap)");
    const std::vector<std::string> match_args = MatchArgs(options_, database_, frames_);
    inputs_ += "--\n" + (stages_as_jobs_  ? SlurmMatchInputs(options_, frames_)
                         : arview_matches ? ArviewMatchInputs(options_, frames_)
                                          : Joined(match_args));
    StageWork run = ColmapStage("match", match_args);
    if (arview_matches) {
      run = [this](std::vector<StageTiming>* steps) {
        MatchWithArview(colmap_, database_, out_dir_, images_.names, options_, cb_, steps);
      };
    } else if (stages_as_jobs_) {
      run = [this](std::vector<StageTiming>*) {
        MatchOnSlurm(options_, JobFiles(), images_.names, PairsToMatch(options_, frames_), cb_);
      };
    }
    // The mapper's inputs are known now: the map stage's record follows the matches'.
    const std::string match_inputs = inputs_;
    mapper_args_ = ColmapMapperArgs(options_, database_, images_.root, sparse_, self_calibrate_);
    in_leaves_ = options_.leaf_size > 0 && frames_ > options_.leaf_size;  // mapping/leaf_mapping.h
    inputs_ += "--\n" + Joined(mapper_args_) +
               (in_leaves_ ? "leaves " + std::to_string(options_.leaf_size) + " " + std::to_string(options_.leaf_overlap) + "\n"
                           : "");
    mapper_inputs_ = inputs_;
    if (self_calibrate_ && cb_.note) {
      cb_.note("the recording's camera is not calibrated (" + recording_.camera.intrinsics_source +
               "): COLMAP refines its focal length, principal point and radial distortion");
    }
    // Half-written matches stay until the next run clears them (clearing needs room to write).
    RunStage("match", match_inputs, [this] { ClearMatches(database_); }, run, true, nullptr);
  }

  // An uncalibrated camera: the focal length COLMAP's adjustment starts from, from the pairs'
  // fundamental matrices (mapping/self_calibration.h); it is part of the map stage's inputs.
  void SelfCalibrationStart() {
    if (!self_calibrate_) return;
    std::string note;
    start_camera_ = StartSelfCalibration(database_, recording_.camera, &note);
    if (cb_.note) cb_.note(note);
    mapper_inputs_ += "--\nself-calibration " + FormatParams(ColmapRadialParams(start_camera_));
  }

  // The board is looked for while COLMAP maps, on the CPU time its mapper leaves (a third of two
  // cores); not when the mapper's stage will be skipped, as its model is then likely made metric.
  void StartBoardSearch() {
    if (options_.scale.from != ScaleFrom::kBoard || (fs::is_directory(sparse_) && stages_.Matches("map", mapper_inputs_)))
      return;
    board_search_.emplace(
        images_.names, [root = images_.root](const std::string& name) { return GreyImageOrNone(root / name); },
        options_.scale.board.inner_corners,
        options_.threads > 0 ? options_.threads : static_cast<int>(std::thread::hardware_concurrency()));
  }

  // COLMAP's mapper (or the leaves mapped and merged), `extra_args` appended to its command line
  // and inputs (a fold retry's start, RetryFoldedMap).
  void Map(const std::vector<std::string>& extra_args) {
    if (in_leaves_) {  // sparse/ is replaced only once the leaves are merged
      const StageWork run = [this](std::vector<StageTiming>* steps) {
        MapInLeaves(options_, {database_, images_.root, out_dir_}, cb_, steps);
      };
      RunStage("map", mapper_inputs_, [] {}, run, fs::is_directory(sparse_), nullptr);
    } else {
      std::vector<std::string> args = mapper_args_;
      args.insert(args.end(), extra_args.begin(), extra_args.end());
      std::error_code ec;
      RunStage(
          "map", extra_args.empty() ? mapper_inputs_ : mapper_inputs_ + Joined(extra_args),
          [&] {
            fs::remove_all(sparse_, ec);
            fs::create_directories(sparse_);
          },
          ColmapStage("map", args), fs::is_directory(sparse_), [&] { fs::remove_all(sparse_, ec); });
    }
    t0_ = std::chrono::steady_clock::now();  // what follows is timed as the map's writing
  }

  // The largest model read and looked at as a whole (first, so that a degenerate model is
  // refused with the reason too).
  void ReadModel() {
    result_.model_dir = LargestModel(sparse_, &result_.models, cb_);
    if (result_.model_dir.empty()) {
      stages_.Forget("map");
      throw ColmapStageError("COLMAP mapper registered no images (no model in " + sparse_.string() +
                                 "): too few matches between the frames? Its output is in " + colmap_.log().string(),
                             "map", colmap_.log(), {});
    }
    options_.cancel.ThrowIfCancelled("COLMAP's stages are finished and kept; the map file was not written");
    std::vector<std::vector<Eigen::Vector2f>> keypoints;
    result_.map = ReadColmapMap(result_.model_dir, database_, images_.lookup, options_.cancel, &keypoints, false);
    result_.map.camera.focus = recording_.camera.focus;  // COLMAP's camera has no focus: the calibration's
    result_.check = CheckMap(result_.map, keypoints, ReadTwoViewGeometries(database_, result_.map));
  }

  // A model that leaves a stretch of the walk out (a fast turn): the mapper once more at a lower
  // triangulation angle (mapping/gap_retry.h); the arguments of the model kept go on with the
  // fold retries' runs.
  void RetryLeftOutStretches() {
    if (in_leaves_) return;
    kept_mapper_args_ = RetryLeftOutFrames(options_, out_dir_, cb_, RetryStages(), &result_);
    t0_ = std::chrono::steady_clock::now();
  }

  // A folded model: the mapper again from other starts (mapping/fold_retries.h); still folded,
  // refused with the check's file written, unless --keep-folded.
  void RetryOrRefuseAFold() {
    if (Folded(result_.check) && options_.fold_retries > 0 && !in_leaves_) {
      RetryFoldedMap(options_.fold_retries, out_dir_, colmap_.log(), cb_, RetryStages(), &result_);
      t0_ = std::chrono::steady_clock::now();
    }
    if (Folded(result_.check) && !options_.keep_folded) {
      WriteMapCheck(result_.check, out_dir_ / kMapCheckFileName);
      throw map::MapError(FoldRefusal(out_dir_, result_));
    }
  }

  // Metric and upright (mapping/metric_frame.h), the refined camera of a self-calibrated map, the
  // rooms, and the map folder's files.
  MapBuildResult MakeMetricAndWrite() {
    const auto read_moved_model = [this] {
      map::Map moved = ReadColmapMap(result_.model_dir, database_, images_.lookup, options_.cancel, nullptr, false);
      moved.camera.focus = recording_.camera.focus;
      return moved;
    };
    MakeMetric(KeyframeImagesIn(result_.map, {images_.root}), board_search_ ? &*board_search_ : nullptr, options_, cb_,
               read_moved_model, &result_);
    if (self_calibrate_) {
      if (cb_.note) cb_.note(RefinedCameraNote(start_camera_, result_.map.camera));
      for (const std::string& problem : ImplausibleIntrinsics(result_.map.camera)) result_.check.warnings.push_back(problem);
      WriteRefinedCamera(start_camera_, result_.map.camera, out_dir_);
    }
    NameRooms(options_.rooms, &result_.map);
    WriteMapFiles(result_, out_dir_, options_, cb_);
    result_.timings.push_back({"write", Seconds(t0_), false});
    return std::move(result_);
  }

 private:
  JobStageFiles JobFiles() const { return {database_, images_.root, out_dir_ / "jobs"}; }

  // The map stage as the retries run it. The kept model stands for the default command's
  // outcome: a re-run skips the stage.
  FoldRetryStages RetryStages() {
    return {[this](const std::vector<std::string>& extra_args) {
              std::vector<std::string> args = kept_mapper_args_;
              args.insert(args.end(), extra_args.begin(), extra_args.end());
              Map(args);
            },
            [this] { ReadModel(); }, [this] { stages_.Forget("map"); },
            [this] { stages_.Save("map", mapper_inputs_); }};
  }

  StageWork ColmapStage(const std::string& name, const std::vector<std::string>& args) {
    return [this, name, args](std::vector<StageTiming>*) { colmap_.Run(name, args, frames_); };
  }

  // `discard` removes what a failed or interrupted run of the stage left half written (a database
  // of some of the frames, a partial model), so that nothing unfinished looks like COLMAP's output.
  // `run` does the stage's work; it may time its own steps into `steps` (else the stage is one).
  void RunStage(const std::string& name, const std::string& stage_inputs, const std::function<void()>& prepare,
                const StageWork& run, bool outputs_exist, const std::function<void()>& discard) {
    t0_ = std::chrono::steady_clock::now();
    if (outputs_exist && stages_.Matches(name, stage_inputs)) {
      if (cb_.note) cb_.note(name + ": inputs unchanged since the last run, skipped");
      result_.timings.push_back({name, 0, true});
      return;
    }
    stages_.Forget(name);
    prepare();
    std::vector<StageTiming> steps;
    try {
      run(&steps);
    } catch (const CancelledError& e) {
      if (discard) discard();
      throw CancelledError(InterruptedStageMessage(options_.cancel, name, result_.timings), e.signal_number());
    } catch (const Error&) {
      if (discard) discard();
      throw;
    }
    stages_.Save(name, stage_inputs);
    if (steps.empty()) steps.push_back({name, Seconds(t0_), false});
    result_.timings.insert(result_.timings.end(), steps.begin(), steps.end());
  }

  const recordings::Recording& recording_;
  const fs::path out_dir_;
  const MapBuildOptions& options_;
  const MapBuildCallbacks& cb_;
  MapBuildResult result_;
  StageRecord stages_;
  ColmapRunner colmap_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();  // the current step's start

  const fs::path database_, sparse_;
  const bool stages_as_jobs_;
  const bool self_calibrate_;
  ImageSet images_;
  int frames_ = 0;
  std::vector<std::string> extract_args_, mapper_args_;
  std::vector<std::string> kept_mapper_args_;  // the gap retry's, when its model is kept
  bool in_leaves_ = false;
  std::string inputs_;         // every stage's inputs so far
  std::string mapper_inputs_;  // the map stage's (+ the focal length self-calibration starts from)
  calib::Camera start_camera_;  // what COLMAP's adjustment starts from
  std::optional<BoardSearchInBackground> board_search_;
};

}  // namespace

MapBuildResult BuildMap(const recordings::Recording& recording, const fs::path& out_dir_arg,
                        const MapBuildOptions& options, const MapBuildCallbacks& cb) {
  // Absolute paths in COLMAP's command lines: the stage records then do not depend on the
  // working directory, and the database names a folder COLMAP's GUI finds from anywhere.
  const fs::path out_dir = fs::absolute(out_dir_arg).lexically_normal();
  options.Check(OptionNames().Nested("mapping"));
  CandidateFrames(recording, options);  // a bad --frames fails before anything is written
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) throw map::MapError(out_dir.string() + ": cannot create the map directory");
  MapBuild build(recording, out_dir, options, cb);
  build.SelectFrames();
  build.Extract();
  build.Match();
  build.SelfCalibrationStart();
  build.StartBoardSearch();
  build.Map({});
  build.ReadModel();
  build.RetryLeftOutStretches();
  build.RetryOrRefuseAFold();
  return build.MakeMetricAndWrite();
}

map::Map ScaleMapFolder(const fs::path& map_dir, const recordings::Recording* recording, const ScaleRequest& request,
                        const MapBuildOptions& options, const MapBuildCallbacks& cb) {
  MapBuildResult result;
  result.map = map::LoadMap(map_dir);
  int models = 0;
  result.model_dir = LargestModel(map_dir / "sparse", &models, {});
  if (result.model_dir.empty())
    throw map::MapError((map_dir / "sparse").string() + ": no COLMAP model (the folder arview map wrote keeps it)");
  // The model moves with the map: it must be the map's own (another map's would be rescaled), and
  // a map file moved after COLMAP takes its model along through that move.
  const std::optional<Sim3> to_map_file = RequireOwnModel(result.model_dir, result.map, map_dir);
  const std::optional<MapCheck> check = ReadMapCheck(map_dir / kMapCheckFileName);
  if (check) result.check = *check;
  std::vector<fs::path> roots{map_dir / "images", map_dir};
  if (recording) roots.push_back(recording->root);
  const MetricFit fit = FitRequested(result.map, request, KeyframeImagesIn(result.map, roots), options, cb);
  options.cancel.ThrowIfCancelled("the map was not changed");
  ApplyMetricFit(fit, &result.map);
  TransformColmapModel(result.model_dir, to_map_file ? Compose(fit.to_metric, *to_map_file) : fit.to_metric,
                       RequestSignature(request), result.map.frame);
  ScaleCheckDistances(fit.to_metric.scale, &result.check);
  WriteMapFiles(result, map_dir, options, cb);
  if (!check) RecheckMap(map_dir);  // a map from before the check: computed now, in metres
  return std::move(result.map);
}

void WriteKeyframesTum(const map::Map& map, const fs::path& file) {
  recordings::Trajectory trajectory;
  for (const map::Keyframe& k : map.keyframes) trajectory.push_back({k.timestamp, k.pose});
  try {
    recordings::WriteTum(trajectory, file, "arview map: the frames COLMAP registered (the keyframes of the map)");
  } catch (const std::exception& e) {
    throw map::MapError(file.string() + ": cannot write keyframes (" + e.what() + ")");
  }
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
