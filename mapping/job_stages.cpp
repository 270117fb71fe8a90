#include "mapping/job_stages.h"

#include <algorithm>

#include "base/atomic_file.h"
#include "base/process.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_stages.h"
#include "mapping/slurm_engine.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// The jobs of one stage, in a fresh <work>/<stage>: one task per chunk, no final job (arview
// merges their databases).
SlurmJobPlan StagePlan(const fs::path& jobs_dir, const std::string& stage) {
  const fs::path work = jobs_dir / stage;
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::create_directories(work);
  SlurmJobPlan plan;
  plan.work_dir = work;
  plan.job_name = "arview-map-" + stage;
  return plan;
}

// Runs the plan with its progress as `stage`'s and the jobs' states as notes.
void RunStageJobs(const SlurmJobPlan& plan, const std::string& stage, const MapBuildOptions& options,
                  const MapBuildCallbacks& cb) {
  SlurmCallbacks slurm;
  slurm.progress = [&](const SlurmProgress& p) {
    if (cb.progress) cb.progress(stage, p.done, p.total);
    if (cb.note && p.done < p.total) cb.note(stage + " jobs on Slurm: " + p.Describe());
  };
  slurm.note = cb.note;
  const int cpus = options.slurm.cpus_per_task > 0 ? options.slurm.cpus_per_task : std::max(1, options.threads);
  RunSlurmJobs(plan, options.slurm, cpus, options.cancel, slurm);
}

int Chunks(const MapBuildOptions& options, int frames) {
  return std::max(1, (frames + options.slurm_chunk - 1) / options.slurm_chunk);
}

Command WithColmap(const std::string& colmap, Command args) {
  args.insert(args.begin(), colmap);
  return args;
}

std::string ColmapOnPath(const MapBuildOptions& options) {
  const std::string colmap = FindExecutable(options.colmap);
  if (colmap.empty()) throw map::MapError("COLMAP not found: '" + options.colmap + "' (the Slurm jobs run it)");
  return colmap;
}

}  // namespace

std::vector<std::pair<int, int>> SplitIntoRuns(int items, int parts) {
  parts = std::max(1, std::min(parts, items));
  std::vector<std::pair<int, int>> runs;
  for (int k = 0, begin = 0; k < parts; ++k) {
    const int size = items / parts + (k < items % parts ? 1 : 0);
    runs.push_back({begin, begin + size});
    begin += size;
  }
  return runs;
}

void ExtractOnSlurm(const calib::Camera& camera, const MapBuildOptions& options, const JobStageFiles& files,
                    const std::vector<std::string>& names, const MapBuildCallbacks& cb) {
  const std::string colmap = ColmapOnPath(options);
  SlurmJobPlan plan = StagePlan(files.work, "extract");
  const fs::path& work = plan.work_dir;
  const auto runs = SplitIntoRuns(static_cast<int>(names.size()), Chunks(options, static_cast<int>(names.size())));
  std::vector<fs::path> databases;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::string list;
    for (int i = runs[k].first; i < runs[k].second; ++i) list += names[i] + "\n";
    const fs::path list_file = work / ("chunk_" + std::to_string(k) + ".txt");
    WriteFileAtomically(list_file, list);
    databases.push_back(work / (std::to_string(k) + ".db"));
    plan.tasks.push_back(WithColmap(colmap, ColmapExtractArgs(camera, options, databases.back(), files.image_root, list_file)));
    plan.task_names.push_back("extraction chunk " + std::to_string(k) + " (frames " + names[runs[k].first] + " to " +
                              names[runs[k].second - 1] + ")");
    // A retry starts from no database: feature_extractor skips the images a database holds.
    plan.task_outputs.push_back(databases.back());
  }
  // A chunk's database must hold every one of its frames' descriptors.
  plan.check_task = [&](int k) -> std::string {
    try {
      const std::vector<std::string> chunk(names.begin() + runs[k].first, names.begin() + runs[k].second);
      ReadImageDescriptors(databases[k], chunk);
      return "";
    } catch (const Error& e) {
      return std::string("its database is incomplete: ") + e.what();
    }
  };
  RunStageJobs(plan, "extract", options, cb);
  // One writer: the merge is built in a staged copy and put in place whole.
  const fs::path staged = files.database.string() + ".merging";
  try {
    CopyColmapDatabase(databases[0], staged);
    for (std::size_t k = 1; k < databases.size(); ++k) {
      options.cancel.ThrowIfCancelled("stopped merging the extraction jobs' databases");
      MergeExtractedImages(staged, databases[k]);
    }
  } catch (...) {
    RemoveColmapDatabase(staged);
    throw;
  }
  RemoveColmapDatabase(files.database);
  fs::rename(staged, files.database);
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::remove(files.work, ec);  // when empty
}

void MatchOnSlurm(const MapBuildOptions& options, const JobStageFiles& files, const std::vector<std::string>& names,
                  const std::vector<ImagePair>& pairs, const MapBuildCallbacks& cb) {
  if (pairs.empty()) return;
  const std::string colmap = ColmapOnPath(options);
  SlurmJobPlan plan = StagePlan(files.work, "match");
  const fs::path& work = plan.work_dir;
  const auto runs = SplitIntoRuns(static_cast<int>(pairs.size()), Chunks(options, static_cast<int>(names.size())));
  std::vector<fs::path> databases;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::string list;
    for (int p = runs[k].first; p < runs[k].second; ++p) list += names[pairs[p].first] + " " + names[pairs[p].second] + "\n";
    const fs::path list_file = work / ("pairs_" + std::to_string(k) + ".txt");
    WriteFileAtomically(list_file, list);
    databases.push_back(work / (std::to_string(k) + ".db"));
    CopyColmapDatabase(files.database, databases.back());
    plan.tasks.push_back({colmap, "matches_importer", "--database_path", databases.back().string(), "--match_list_path",
                          list_file.string(), "--match_type", "pairs", "--SiftMatching.use_gpu", "0",
                          "--SiftMatching.num_threads", std::to_string(options.threads)});
    plan.task_names.push_back("matching block " + std::to_string(k) + " (" + std::to_string(runs[k].second - runs[k].first) +
                              " pairs)");
  }
  RunStageJobs(plan, "match", options, cb);
  for (const fs::path& part : databases) {
    options.cancel.ThrowIfCancelled("stopped adding the matching jobs' pairs");
    MergeVerifiedPairs(files.database, part);
  }
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::remove(files.work, ec);  // when empty
}

}  // namespace arview::mapping
