// `arview map` as the sequence of its stages: BuildMap runs one MapBuild, whose methods are the
// stages in the order they run over the state they hand on. What a stage is run with (its record,
// COLMAP as a child process, the command lines, arview's matching, the metric step and the map
// folder's files) is apart from it, declared in mapping/map_build_stages.h.

#include "mapping/colmap_pipeline.h"

#include <chrono>
#include <optional>
#include <thread>

#include "base/atomic_file.h"
#include "mapping/colmap_model.h"
#include "mapping/outlying_poses.h"
#include "mapping/fold_retries.h"
#include "mapping/gap_retry.h"
#include "mapping/job_stages.h"
#include "mapping/leaf_mapping.h"
#include "mapping/map_build_stages.h"
#include "mapping/self_calibration.h"

namespace arview::mapping {

namespace fs = std::filesystem;

MatcherKind ParseMatcherKind(const std::string& text) {
  return ParseEnum<MatcherKind, map::MapError>(text, "--matcher");
}

MatchEngine ParseMatchEngine(const std::string& text) {
  return ParseEnum<MatchEngine, map::MapError>(text, "--match-engine");
}

namespace {

std::string Joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += a + "\n";
  return s;
}

void ClearMatches(const fs::path& database) {
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite)
      .Execute("DELETE FROM matches; DELETE FROM two_view_geometries;", "clear old matches");
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
    // A venue's pairs (within rooms, across them from the descriptor index) where COLMAP matches.
    const bool listed_pairs = !stages_as_jobs_ && !arview_matches && VenuePairsWanted(options_, frames_) &&
                              NamesFitAMatchList(images_.names);
    const std::vector<std::string> match_args = MatchArgs(options_, database_, frames_);
    inputs_ += "--\n" + (stages_as_jobs_  ? SlurmMatchInputs(options_, frames_)
                         : arview_matches ? ArviewMatchInputs(options_, frames_)
                         : listed_pairs   ? ListedPairsMatchInputs(options_, frames_)
                                          : Joined(match_args));
    StageWork run = ColmapStage("match", match_args);
    if (arview_matches) {
      run = [this](std::vector<StageTiming>* steps) {
        MatchWithArview(colmap_, database_, out_dir_, images_.names, images_.lookup, options_, cb_, steps);
      };
    } else if (stages_as_jobs_) {
      run = [this](std::vector<StageTiming>*) {
        MatchOnSlurm(options_, JobFiles(), images_.names,
                     PairsToMatch(options_, images_.names, images_.lookup, database_, cb_), cb_);
      };
    } else if (listed_pairs) {
      run = [this](std::vector<StageTiming>*) {
        MatchListedPairsWithColmap(colmap_, database_, out_dir_, images_.names, images_.lookup, options_, cb_);
      };
    }
    // The mapper's inputs are known now: the map stage's record follows the matches'.
    const std::string match_inputs = inputs_;
    mapper_args_ = ColmapMapperArgs(options_, database_, images_.root, sparse_, self_calibrate_);
    in_leaves_ = options_.leaf_size > 0 && frames_ > options_.leaf_size;  // mapping/leaf_mapping.h
    inputs_ += "--\n" + Joined(mapper_args_) +
               (in_leaves_ ? "leaves " + std::to_string(options_.leaf_size) + " " + std::to_string(options_.leaf_overlap) +
                                 (options_.LeavesCutWithinRooms() ? " within rooms" : "") + "\n"
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
        MapInLeaves(options_, {database_, images_.root, out_dir_, images_.lookup}, cb_, steps);
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
    ReadResultModel();
  }

  // The model in result_.model_dir as the result's map, with its self-check.
  void ReadResultModel() {
    CheckedModel model = ReadCheckedModel(result_.model_dir, database_, images_.lookup, options_.cancel);
    result_.map = std::move(model.map);
    result_.map.camera.focus = recording_.camera.focus;  // COLMAP's camera has no focus: the calibration's
    result_.check = std::move(model.check);
  }

  // A frame the adjustment left in a local minimum, posed again on its points with them held
  // (mapping/outlying_poses.h), and the model read again. Not in a folded model (one kept with
  // --keep-folded): a fold is a stretch of the path turned together, for the fold retries.
  void RePoseOutlyingFrames() {
    if (Folded(result_.check)) return;
    const std::vector<RePosedImage> re_posed = RePoseOutlyingImagesIn(result_.model_dir);
    for (const RePosedImage& image : re_posed)
      if (cb_.note) cb_.note(Describe(image));
    if (std::any_of(re_posed.begin(), re_posed.end(), [](const RePosedImage& r) { return r.kept; })) ReadResultModel();
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
      for (const std::string& problem : ImplausibleIntrinsics(result_.map.camera)) result_.check.warnings.push_back("is self-calibrated implausibly: " + problem);
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
  build.RePoseOutlyingFrames();
  return build.MakeMetricAndWrite();
}

}  // namespace arview::mapping
