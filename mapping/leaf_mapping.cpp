#include "mapping/leaf_mapping.h"

#include <chrono>
#include <set>

#include "base/atomic_file.h"
#include "base/process.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_stages.h"

namespace arview::mapping {

namespace fs = std::filesystem;

MapEngine ParseMapEngine(const std::string& text) { return ParseEnum<MapEngine, map::MapError>(text, "--engine"); }

namespace {

constexpr const char* kMergeFailed = "=> Merge failed";  // model_merger's line when it could not merge

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What is run, where, for one map built in leaves.
struct LeafPlan {
  fs::path work;                          // <out>/leaves
  std::vector<std::vector<std::string>> leaf_images;  // each leaf's image names (core, then overlap)
  std::vector<Command> leaf_commands;     // COLMAP argument lists, without the executable
  std::vector<int> merge_order;
  std::vector<Command> merge_commands;    // model_merger per leaf after the first, triangulator, adjuster
  fs::path merged_last, adjusted;

  fs::path LeafModel(int leaf) const { return work / std::to_string(leaf) / "sparse" / "0"; }
  fs::path Merged(int step) const { return work / ("merged_" + std::to_string(step)); }
  std::string LeafName(int leaf) const {
    return "leaf " + std::to_string(leaf) + " (" + std::to_string(leaf_images[leaf].size()) + " frames)";
  }
};

std::string RefineFlag(const MapBuildOptions& options) { return options.refine_intrinsics ? "1" : "0"; }

// The merge's alignment counts an observation as agreeing within 4 px (the mapper's own
// filter_max_reproj_error), not model_merger's default 64 px: with 64, templeRing's leaves were
// merged 1.5 degrees apart, a misalignment too large for the triangulation's 4 px filter to keep
// any track across it, so the bundle adjustment after could not close it (docs/mapping.md).
Command MergeCommand(const fs::path& a, const fs::path& b, const fs::path& out) {
  return {"model_merger", "--input_path1", a.string(), "--input_path2", b.string(), "--output_path", out.string(),
          "--max_reproj_error", "4"};
}

Command TriangulateCommand(const MapBuildOptions& options, const LeafMappingPaths& paths, const fs::path& in,
                           const fs::path& out) {
  const std::string refine = RefineFlag(options);
  return {"point_triangulator", "--database_path", paths.database.string(), "--image_path",
          paths.image_root.string(), "--input_path", in.string(), "--output_path", out.string(),
          // The leaves' own points kept (model_merger joined their tracks in the shared frames)
          // and completed from the database's matches: re-triangulated from the matches instead,
          // then adjusted, templeRing's keyframes came out 10-25 % further from the ground truth,
          // and the single mapper's own model as far (docs/mapping.md, "The merge keeps the
          // leaves' points").
          "--clear_points", "0", "--Mapper.num_threads", std::to_string(options.threads),
          "--Mapper.ba_refine_focal_length", refine, "--Mapper.ba_refine_principal_point", refine,
          "--Mapper.ba_refine_extra_params", refine};
}

Command AdjustCommand(const MapBuildOptions& options, const fs::path& in, const fs::path& out) {
  const std::string refine = RefineFlag(options);
  return {"bundle_adjuster", "--input_path", in.string(), "--output_path", out.string(),
          "--BundleAdjustment.refine_focal_length", refine, "--BundleAdjustment.refine_principal_point", refine,
          "--BundleAdjustment.refine_extra_params", refine};
}

LeafPlan PlanLeaves(const MapBuildOptions& options, const LeafMappingPaths& paths, const MapBuildCallbacks& cb) {
  const MatchGraph graph = BuildMatchGraph(ReadMatchGraph(paths.database));
  const Partition partition = PartitionMatchGraph(graph, {options.leaf_size, options.leaf_overlap});
  LeafPlan plan;
  plan.work = paths.out_dir / "leaves";
  std::error_code ec;
  fs::remove_all(plan.work, ec);
  std::string sizes;
  long long total_weight = 0;
  for (const auto& e : graph.edges) total_weight += e.weight;
  for (std::size_t i = 0; i < partition.leaves.size(); ++i) {
    const Leaf& leaf = partition.leaves[i];
    std::vector<std::string> names;
    std::string list;
    for (const int v : leaf.All()) {
      names.push_back(graph.names[v]);
      list += graph.names[v] + "\n";
    }
    const fs::path dir = plan.work / std::to_string(i);
    fs::create_directories(dir / "sparse");
    WriteFileAtomically(dir / "images.txt", list);
    Command mapper = ColmapMapperArgs(options, paths.database, paths.image_root, dir / "sparse");
    mapper.insert(mapper.end(), {"--image_list_path", (dir / "images.txt").string(), "--Mapper.multiple_models", "0"});
    plan.leaf_commands.push_back(std::move(mapper));
    plan.leaf_images.push_back(std::move(names));
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(leaf.core.size()) + "+" + std::to_string(leaf.overlap.size());
  }
  plan.merge_order = MergeOrder(partition);
  fs::path merged = plan.LeafModel(plan.merge_order.front());
  for (std::size_t step = 1; step < plan.merge_order.size(); ++step) {
    fs::create_directories(plan.Merged(static_cast<int>(step)));
    plan.merge_commands.push_back(MergeCommand(merged, plan.LeafModel(plan.merge_order[step]), plan.Merged(static_cast<int>(step))));
    merged = plan.Merged(static_cast<int>(step));
  }
  plan.merged_last = merged;
  const fs::path triangulated = plan.work / "triangulated";
  plan.adjusted = plan.work / "adjusted";
  fs::create_directories(triangulated);
  fs::create_directories(plan.adjusted);
  plan.merge_commands.push_back(TriangulateCommand(options, paths, merged, triangulated));
  plan.merge_commands.push_back(AdjustCommand(options, triangulated, plan.adjusted));
  if (cb.note) {
    cb.note(std::to_string(graph.names.size()) + " frames mapped as " + std::to_string(partition.leaves.size()) +
            " leaves of at most " + std::to_string(options.leaf_size) + " (frames + overlap: " + sizes +
            "); the cut between them holds " + std::to_string(partition.cut_weight) + " of " +
            std::to_string(total_weight) + " inliers");
  }
  return plan;
}

// The COLMAP image ids a model registered; a leaf without a model is a MapError naming it.
std::set<std::uint32_t> RegisteredIds(const fs::path& model, const std::string& what, const fs::path& log) {
  if (!fs::exists(model / "images.bin")) {
    throw map::MapError(what + ": COLMAP mapper registered no images (no model in " + model.string() +
                        "): too few matches between its frames? Its output is in " + log.string());
  }
  std::set<std::uint32_t> ids;
  for (const auto& keyframe : ReadColmapCameraPath(model)) ids.insert(keyframe.colmap_image_id);
  return ids;
}

// model_merger exits 0 when it cannot merge, leaving the first model as it was: each step's
// output must hold every image the leaves merged so far registered.
void CheckMerges(const LeafPlan& plan, const std::vector<fs::path>& leaf_logs, int steps_done, const fs::path& merge_log) {
  std::set<std::uint32_t> expected = RegisteredIds(plan.LeafModel(plan.merge_order[0]), plan.LeafName(plan.merge_order[0]),
                                                   leaf_logs[plan.merge_order[0]]);
  for (int step = 1; step <= steps_done; ++step) {
    const int leaf = plan.merge_order[step];
    const std::set<std::uint32_t> ids = RegisteredIds(plan.LeafModel(leaf), plan.LeafName(leaf), leaf_logs[leaf]);
    int shared = 0;
    for (const auto id : ids) shared += static_cast<int>(expected.count(id));
    expected.insert(ids.begin(), ids.end());
    const std::uint64_t merged = fs::exists(plan.Merged(step) / "images.bin") ? CountRegisteredImages(plan.Merged(step)) : 0;
    if (merged != expected.size()) {
      throw map::MapError("COLMAP model_merger could not merge " + plan.LeafName(leaf) + " into the leaves before it (" +
                          std::to_string(merged) + " of " + std::to_string(expected.size()) +
                          " registered images in its output; the leaves share " + std::to_string(shared) +
                          " registered images, a merge needs 3 that agree): a larger --leaf-overlap may help; its output "
                          "is in " + merge_log.string());
    }
  }
}

void CheckAdjusted(const LeafPlan& plan, const fs::path& log) {
  const std::uint64_t merged = CountRegisteredImages(plan.merged_last);
  const std::uint64_t adjusted = fs::exists(plan.adjusted / "images.bin") ? CountRegisteredImages(plan.adjusted) : 0;
  if (adjusted != merged) {
    throw map::MapError("the merged leaves' triangulation and bundle adjustment left " + std::to_string(adjusted) +
                        " of " + std::to_string(merged) + " images; COLMAP's output is in " + log.string());
  }
}

// Why a leaf's model cannot be merged (missing, empty, a file damaged), or empty when it can.
std::string LeafModelProblem(const fs::path& model) {
  if (!fs::exists(model / "images.bin"))
    return "COLMAP mapper registered no images (no model in " + model.string() + "): too few matches between its frames?";
  try {
    RequireReadableModel(model);
  } catch (const Error& e) {
    return std::string("its model is damaged: ") + e.what();
  }
  if (CountRegisteredImages(model) == 0) return "its model in " + model.string() + " holds no registered image";
  return "";
}

Command WithExecutable(const std::string& colmap, Command args) {
  args.insert(args.begin(), colmap);
  return args;
}

// Leaves one after another, each merge step checked as it is done.
void RunLocally(const MapBuildOptions& options, const LeafMappingPaths& paths, const LeafPlan& plan,
                const MapBuildCallbacks& cb, std::vector<StageTiming>* steps) {
  const fs::path log = paths.out_dir / "colmap.log";
  auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < plan.leaf_commands.size(); ++i) {
    if (cb.note) cb.note("mapping " + plan.LeafName(static_cast<int>(i)) + " of " + std::to_string(plan.leaf_commands.size()));
    try {
      RunColmap(options, paths.out_dir, "map", plan.leaf_commands[i], static_cast<int>(plan.leaf_images[i].size()), cb);
    } catch (const ColmapStageError& e) {
      throw ColmapStageError(plan.LeafName(static_cast<int>(i)) + ": " + e.what(), e.stage, e.log, e.log_tail);
    }
  }
  steps->push_back({"map leaves", SecondsSince(t0), false});
  t0 = std::chrono::steady_clock::now();
  const std::vector<fs::path> leaf_logs(plan.leaf_commands.size(), log);
  const int merges = static_cast<int>(plan.merge_order.size()) - 1;
  for (int step = 1; step <= merges; ++step) {
    RunColmap(options, paths.out_dir, "merge", plan.merge_commands[step - 1], 0, cb);
    CheckMerges(plan, leaf_logs, step, log);
  }
  for (std::size_t c = merges; c < plan.merge_commands.size(); ++c) RunColmap(options, paths.out_dir, "merge", plan.merge_commands[c], 0, cb);
  CheckAdjusted(plan, log);
  steps->push_back({"merge", SecondsSince(t0), false});
}

// The leaves as one Slurm job array and the merge as one job after it.
void RunOnSlurm(const MapBuildOptions& options, const LeafPlan& plan, const MapBuildCallbacks& cb,
                std::vector<StageTiming>* steps) {
  const std::string colmap = FindExecutable(options.colmap);
  if (colmap.empty()) throw map::MapError("COLMAP not found: '" + options.colmap + "' (the Slurm jobs run it)");
  SlurmJobPlan jobs;
  jobs.work_dir = plan.work;
  jobs.job_name = "arview-map-leaves";
  for (std::size_t i = 0; i < plan.leaf_commands.size(); ++i) {
    jobs.tasks.push_back(WithExecutable(colmap, plan.leaf_commands[i]));
    jobs.task_names.push_back(plan.LeafName(static_cast<int>(i)));
    jobs.task_outputs.push_back(plan.LeafModel(static_cast<int>(i)));
  }
  for (const auto& command : plan.merge_commands) jobs.final_commands.push_back(WithExecutable(colmap, command));
  jobs.final_name = "the merge of the leaves";
  jobs.final_failure_marker = kMergeFailed;
  const int cpus = options.slurm.cpus_per_task > 0 ? options.slurm.cpus_per_task : std::max(1, options.threads);
  // Each leaf's model is read as soon as its job completes: one that is missing or damaged fails
  // the leaf (and is mapped once more) before the merge takes it.
  jobs.check_task = [&plan](int leaf) { return LeafModelProblem(plan.LeafModel(leaf)); };
  const auto t0 = std::chrono::steady_clock::now();
  SlurmCallbacks slurm;
  slurm.progress = [&](const SlurmProgress& p) {
    if (cb.progress) cb.progress("map", p.done, p.total);
    if (cb.note && p.done < p.total) cb.note("leaves on Slurm: " + p.Describe());
  };
  slurm.note = cb.note;
  std::vector<fs::path> leaf_logs;
  for (std::size_t i = 0; i < plan.leaf_commands.size(); ++i) leaf_logs.push_back(TaskLog(jobs, static_cast<int>(i)));
  try {
    RunSlurmJobs(jobs, options.slurm, cpus, options.cancel, slurm);
  } catch (const SlurmError& e) {
    // The merge job fails when a leaf could not be merged: say which.
    if (std::string(e.what()).rfind(jobs.final_name, 0) == 0 && fs::exists(FinalLog(jobs)))
      CheckMerges(plan, leaf_logs, static_cast<int>(plan.merge_order.size()) - 1, FinalLog(jobs));
    throw;
  }
  CheckMerges(plan, leaf_logs, static_cast<int>(plan.merge_order.size()) - 1, FinalLog(jobs));
  CheckAdjusted(plan, FinalLog(jobs));
  steps->push_back({"map leaves + merge (slurm)", SecondsSince(t0), false});
}

}  // namespace

std::vector<int> MergeOrder(const Partition& partition) {
  const int leaves = static_cast<int>(partition.leaves.size());
  std::vector<std::set<int>> images(leaves);
  for (int i = 0; i < leaves; ++i) {
    const auto all = partition.leaves[i].All();
    images[i].insert(all.begin(), all.end());
  }
  std::vector<int> order{0};
  std::set<int> merged = images[0];
  std::vector<char> done(leaves, 0);
  done[0] = 1;
  while (static_cast<int>(order.size()) < leaves) {
    int best = -1, best_shared = -1;
    for (int i = 0; i < leaves; ++i) {
      if (done[i]) continue;
      int shared = 0;
      for (const int v : images[i]) shared += static_cast<int>(merged.count(v));
      if (shared > best_shared) best = i, best_shared = shared;
    }
    done[best] = 1;
    order.push_back(best);
    merged.insert(images[best].begin(), images[best].end());
  }
  return order;
}

void MapInLeaves(const MapBuildOptions& options, const LeafMappingPaths& paths, const MapBuildCallbacks& cb,
                 std::vector<StageTiming>* steps) {
  const LeafPlan plan = PlanLeaves(options, paths, cb);
  if (options.engine == MapEngine::kSlurm) {
    RunOnSlurm(options, plan, cb, steps);
  } else {
    RunLocally(options, paths, plan, cb, steps);
  }
  // Only now is the map folder's model replaced: the new sparse/ is made whole beside it, then the
  // old one renamed aside and the new one into its place (a crash between the renames leaves both
  // whole, as sparse.old/ and sparse.new/).
  const fs::path sparse = paths.out_dir / "sparse", fresh = paths.out_dir / "sparse.new", old = paths.out_dir / "sparse.old";
  std::error_code ec;
  fs::remove_all(fresh, ec);
  fs::remove_all(old, ec);
  fs::create_directories(fresh);
  fs::rename(plan.adjusted, fresh / "0");
  if (fs::exists(sparse)) fs::rename(sparse, old);
  fs::rename(fresh, sparse);
  fs::remove_all(old, ec);
}

}  // namespace arview::mapping
