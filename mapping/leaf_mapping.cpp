#include "mapping/leaf_mapping.h"

#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <set>

#include "base/atomic_file.h"
#include "base/process.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_stages.h"
#include "mapping/fold_retries.h"
#include "mapping/map_check.h"
#include "mapping/leaf_merge.h"
#include "mapping/map_build_stages.h"

namespace arview::mapping {

namespace fs = std::filesystem;

MapEngine ParseMapEngine(const std::string& text) { return ParseEnum<MapEngine, map::MapError>(text, "--engine"); }

namespace {

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// `from`'s bytes appended to `to` (a log gathered from a job's; a missing `from` adds nothing).
void AppendFile(const fs::path& from, const fs::path& to) {
  std::ifstream in(from, std::ios::binary);
  if (!in) return;
  std::ofstream out(to, std::ios::binary | std::ios::app);
  out << in.rdbuf();
}

// The merged leaves are triangulated and adjusted twice: after the first adjustment the leaves
// agree better, so the second triangulation joins more tracks across them for the second
// adjustment to hold them by. On the rendered venue's leaves of 200 the second round took each
// room's error from 2.36 / 2.66 / 4.61 mm to 1.59 / 2.17 / 3.25 mm (docs/mapping.md).
constexpr int kGlobalRounds = 2;

// What is run, where, for one map built in leaves.
struct LeafPlan {
  fs::path work;                          // <out>/leaves
  std::vector<std::vector<std::string>> leaf_images;  // each leaf's image names (core, then overlap)
  std::vector<LeafToRetry> retry;         // each leaf as its model's retries see it
  std::vector<Command> leaf_commands;     // COLMAP argument lists, without the executable
  std::vector<int> merge_order;
  // Over the merged leaves, after the merge: point_triangulator and bundle_adjuster, then both
  // once more (kGlobalRounds).
  std::vector<Command> global_steps;
  fs::path merged, adjusted;

  fs::path LeafModel(int leaf) const { return work / std::to_string(leaf) / "sparse" / "0"; }
  std::string LeafName(int leaf) const {
    return "leaf " + std::to_string(leaf) + " (" + std::to_string(leaf_images[leaf].size()) + " frames)";
  }
};

std::string RefineFlag(const MapBuildOptions& options) { return options.refine_intrinsics ? "1" : "0"; }

Command TriangulateCommand(const MapBuildOptions& options, const LeafMappingPaths& paths, const fs::path& in,
                           const fs::path& out) {
  const std::string refine = RefineFlag(options);
  return {"point_triangulator", "--database_path", paths.database.string(), "--image_path",
          paths.image_root.string(), "--input_path", in.string(), "--output_path", out.string(),
          // The leaves' own points kept (the merge joined their tracks in the shared frames)
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

// A leaf's frames (COLMAP image id, name), those with the most inliers to the leaf's other frames
// first: where a new mapper run best starts.
std::vector<std::pair<std::uint32_t, std::string>> BestMatchedFirst(const MatchGraph& graph, const DatabaseMatchGraph& database,
                                                                    const Leaf& leaf) {
  const std::vector<int> all = leaf.All();
  std::set<int> in_leaf(all.begin(), all.end());
  std::map<int, long long> weight;
  for (const GraphEdge& e : graph.edges) {
    if (!in_leaf.count(e.a) || !in_leaf.count(e.b)) continue;
    weight[e.a] += e.weight;
    weight[e.b] += e.weight;
  }
  std::vector<int> order = all;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return weight[a] > weight[b]; });
  std::vector<std::pair<std::uint32_t, std::string>> starts;
  for (const int v : order) starts.emplace_back(database.images[static_cast<std::size_t>(v)].first, graph.names[v]);
  return starts;
}

LeafPlan PlanLeaves(const MapBuildOptions& options, const LeafMappingPaths& paths, const MapBuildCallbacks& cb) {
  const DatabaseMatchGraph database = ReadMatchGraph(paths.database);
  const MatchGraph graph = BuildMatchGraph(database);
  const bool by_room = options.LeavesCutWithinRooms();
  const Partition partition = PartitionMatchGraph(
      graph, {options.leaf_size, options.leaf_overlap, by_room ? RoomOfEachImage(options, graph.names, paths.frames) : std::vector<int>{}});
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
    plan.retry.push_back(LeafToRetry{"", dir, static_cast<int>(leaf.All().size()), BestMatchedFirst(graph, database, leaf)});
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(leaf.core.size()) + "+" + std::to_string(leaf.overlap.size());
  }
  for (std::size_t i = 0; i < plan.retry.size(); ++i) plan.retry[i].name = plan.LeafName(static_cast<int>(i));
  plan.merge_order = MergeOrder(partition);
  plan.merged = plan.work / "merged";
  plan.adjusted = plan.work / "adjusted";
  fs::path in = plan.merged;
  for (int round = 1; round <= kGlobalRounds; ++round) {
    const std::string suffix = round == kGlobalRounds ? "" : "_" + std::to_string(round);
    const fs::path triangulated = plan.work / ("triangulated" + suffix), adjusted = plan.work / ("adjusted" + suffix);
    fs::create_directories(triangulated);
    fs::create_directories(adjusted);
    plan.global_steps.push_back(TriangulateCommand(options, paths, in, triangulated));
    plan.global_steps.push_back(AdjustCommand(options, triangulated, adjusted));
    in = adjusted;
  }
  if (cb.note) {
    cb.note(std::to_string(graph.names.size()) + " frames mapped as " + std::to_string(partition.leaves.size()) +
            " leaves of at most " + std::to_string(options.leaf_size) + (by_room ? ", cut within rooms" : "") +
            " (frames + overlap: " + sizes +
            "); the cut between them holds " + std::to_string(partition.cut_weight) + " of " +
            std::to_string(total_weight) + " inliers");
  }
  return plan;
}

// A leaf without a model is a MapError naming it and its mapper's output (ReadSparseModel reads the model after).
void RequireLeafModel(const fs::path& model, const std::string& what, const fs::path& log) {
  if (!fs::exists(model / "images.bin")) {
    throw map::MapError(what + ": COLMAP mapper registered no images (no model in " + model.string() +
                        "): too few matches between its frames? Its output is in " + log.string());
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

// A leaf's model read and looked at as BuildMap looks at a map (mapping/map_check.h); false
// when it has no model to look at (the merge says why).
bool ReadAndCheckLeaf(const LeafMappingPaths& paths, const LeafPlan& plan, int leaf, MapBuildResult* result) {
  if (!LeafModelProblem(plan.LeafModel(leaf)).empty()) return false;
  CheckedModel model = ReadCheckedModel(plan.LeafModel(leaf), paths.database, paths.frames);
  result->map = std::move(model.map);
  result->check = std::move(model.check);
  return true;
}

// The leaves' models joined one by one in the merge order into <work>/merged (mapping/leaf_merge.h).
// A leaf that cannot be merged is a MapError naming it and why.
void MergeLeaves(const LeafPlan& plan, const std::vector<fs::path>& leaf_logs, const MapBuildCallbacks& cb) {
  const auto read_leaf = [&](int leaf) {
    RequireLeafModel(plan.LeafModel(leaf), plan.LeafName(leaf), leaf_logs[static_cast<std::size_t>(leaf)]);
    return ReadSparseModel(plan.LeafModel(leaf));
  };
  SparseModel merged = read_leaf(plan.merge_order.front());
  for (std::size_t step = 1; step < plan.merge_order.size(); ++step) {
    const int leaf = plan.merge_order[step];
    const SparseModel model = read_leaf(leaf);
    LeafAlignment alignment = AlignLeaf(merged, model);
    if (!alignment.problem.empty()) {
      throw map::MapError("could not merge " + plan.LeafName(leaf) + ", of which its mapper registered " +
                          std::to_string(model.images.size()) + ", into the leaves before it: " + alignment.problem +
                          "; a larger --leaf-overlap may help (the leaves' models are in " + plan.work.string() + ")");
    }
    JoinLeaf(&merged, model, &alignment);
    if (cb.note) cb.note("merged " + plan.LeafName(leaf) + ": " + alignment.report.Describe());
  }
  std::error_code ec;
  fs::remove_all(plan.merged, ec);
  WriteSparseModel(merged, plan.merged);
}

void CheckAdjusted(const LeafPlan& plan, const fs::path& log) {
  const std::uint64_t merged = CountRegisteredImages(plan.merged);
  const std::uint64_t adjusted = fs::exists(plan.adjusted / "images.bin") ? CountRegisteredImages(plan.adjusted) : 0;
  if (adjusted != merged) {
    throw map::MapError("the merged leaves' triangulation and bundle adjustment left " + std::to_string(adjusted) +
                        " of " + std::to_string(merged) + " images; COLMAP's output is in " + log.string());
  }
}

Command WithExecutable(const std::string& colmap, Command args) {
  args.insert(args.begin(), colmap);
  return args;
}

// Leaves one after another, each merge step checked as it is done.
void RunLocally(const MapBuildOptions& options, const LeafMappingPaths& paths, const LeafPlan& plan,
                const MapBuildCallbacks& cb, std::vector<StageTiming>* steps) {
  const fs::path log = paths.out_dir / "colmap.log";
  // Each leaf's mapper writes its own log (<out>/leaves/<i>/colmap.log): its fold retries read the
  // initial pair of its last run there.
  const auto leaf_dir = [&plan](int leaf) { return plan.work / std::to_string(leaf); };
  const auto map_leaf = [&](int leaf, const Command& extra) {
    Command command = plan.leaf_commands[static_cast<std::size_t>(leaf)];
    command.insert(command.end(), extra.begin(), extra.end());
    try {
      RunColmap(options, leaf_dir(leaf), "map", command, static_cast<int>(plan.leaf_images[leaf].size()), cb);
    } catch (const ColmapStageError& e) {
      throw ColmapStageError(plan.LeafName(leaf) + ": " + e.what(), e.stage, e.log, e.log_tail);
    }
  };
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < static_cast<int>(plan.leaf_commands.size()); ++i) {
    if (cb.note) cb.note("mapping " + plan.LeafName(i) + " of " + std::to_string(plan.leaf_commands.size()));
    map_leaf(i, {});
  }
  const auto leaf_log = [&](int leaf) { return leaf_dir(leaf) / "colmap.log"; };
  RetryLeafModels(options, plan.retry, cb,
                  {[&](int leaf, MapBuildResult* r) { return ReadAndCheckLeaf(paths, plan, leaf, r); }, map_leaf, leaf_log});
  steps->push_back({"map leaves", SecondsSince(t0), false});
  t0 = std::chrono::steady_clock::now();
  std::vector<fs::path> leaf_logs;
  for (int i = 0; i < static_cast<int>(plan.leaf_commands.size()); ++i) leaf_logs.push_back(leaf_log(i));
  MergeLeaves(plan, leaf_logs, cb);
  for (const Command& step : plan.global_steps) RunColmap(options, paths.out_dir, "merge", step, 0, cb);
  CheckAdjusted(plan, log);
  steps->push_back({"merge", SecondsSince(t0), false});
}

SlurmCallbacks SlurmProgressAs(const std::string& stage, const std::string& what, const MapBuildCallbacks& cb) {
  SlurmCallbacks slurm;
  slurm.progress = [&cb, stage, what](const SlurmProgress& p) {
    if (cb.progress) cb.progress(stage, p.done, p.total);
    if (cb.note && p.done < p.total) cb.note(what + " on Slurm: " + p.Describe());
  };
  slurm.note = cb.note;
  return slurm;
}

// The leaves as one Slurm job array; their merge here (the models read, aligned and joined: a
// few seconds); then the global triangulation as a job and the bundle adjustment as the job after it.
void RunOnSlurm(const MapBuildOptions& options, const LeafMappingPaths& paths, const LeafPlan& plan,
                const MapBuildCallbacks& cb, std::vector<StageTiming>* steps) {
  const std::string colmap = FindExecutable(options.colmap);
  if (colmap.empty()) throw map::MapError("COLMAP not found: '" + options.colmap + "' (the Slurm jobs run it)");
  const int cpus = options.slurm.cpus_per_task > 0 ? options.slurm.cpus_per_task : std::max(1, options.threads);
  SlurmJobPlan leaves;
  leaves.work_dir = plan.work;
  leaves.job_name = "arview-map-leaves";
  for (std::size_t i = 0; i < plan.leaf_commands.size(); ++i) {
    leaves.tasks.push_back(WithExecutable(colmap, plan.leaf_commands[i]));
    leaves.task_names.push_back(plan.LeafName(static_cast<int>(i)));
    leaves.task_outputs.push_back(plan.LeafModel(static_cast<int>(i)));
  }
  // Each leaf's model is read as soon as its job completes: one that is missing or damaged fails
  // the leaf (and is mapped once more) before the merge takes it.
  leaves.check_task = [&plan](int leaf) { return LeafModelProblem(plan.LeafModel(leaf)); };
  auto t0 = std::chrono::steady_clock::now();
  RunSlurmJobs(leaves, options.slurm, cpus, options.cancel, SlurmProgressAs("map", "leaves", cb));
  // A folded leaf is mapped again as a job of its own; its runs' output gathered in
  // <out>/leaves/<i>/mapper.log, where its fold retries read each run's initial pair.
  const auto leaf_log = [&plan](int leaf) { return plan.work / std::to_string(leaf) / "mapper.log"; };
  for (int i = 0; i < static_cast<int>(plan.leaf_commands.size()); ++i) AppendFile(TaskLog(leaves, i), leaf_log(i));
  int reruns = 0;
  const auto map_again = [&](int leaf, const Command& extra) {
    SlurmJobPlan again = leaves;
    again.work_dir = plan.work / ("again_" + std::to_string(reruns++));
    again.tasks = {leaves.tasks[static_cast<std::size_t>(leaf)]};
    again.tasks.front().insert(again.tasks.front().end(), extra.begin(), extra.end());
    again.task_names = {plan.LeafName(leaf) + ", mapped again"};
    again.task_outputs.clear();
    again.check_task = [&plan, leaf](int) { return LeafModelProblem(plan.LeafModel(leaf)); };
    try {
      RunSlurmJobs(again, options.slurm, cpus, options.cancel, SlurmProgressAs("map", plan.LeafName(leaf), cb));
    } catch (...) {
      AppendFile(TaskLog(again, 0), leaf_log(leaf));
      throw;
    }
    AppendFile(TaskLog(again, 0), leaf_log(leaf));
  };
  RetryLeafModels(options, plan.retry, cb,
                  {[&](int leaf, MapBuildResult* r) { return ReadAndCheckLeaf(paths, plan, leaf, r); }, map_again, leaf_log});
  steps->push_back({"map leaves (slurm)", SecondsSince(t0), false});

  t0 = std::chrono::steady_clock::now();
  std::vector<fs::path> leaf_logs;
  for (int i = 0; i < static_cast<int>(plan.leaf_commands.size()); ++i) leaf_logs.push_back(leaf_log(i));
  MergeLeaves(plan, leaf_logs, cb);
  steps->push_back({"merge", SecondsSince(t0), false});

  t0 = std::chrono::steady_clock::now();
  SlurmJobPlan global;
  global.work_dir = plan.work / "global";
  global.job_name = "arview-map-merge";
  global.tasks = {WithExecutable(colmap, plan.global_steps.front())};
  global.task_names = {"the triangulation of the merged leaves"};
  for (std::size_t i = 1; i < plan.global_steps.size(); ++i)
    global.final_commands.push_back(WithExecutable(colmap, plan.global_steps[i]));
  global.final_name = "the adjustment of the merged leaves (and their second triangulation and adjustment)";
  RunSlurmJobs(global, options.slurm, cpus, options.cancel, SlurmProgressAs("merge", "the merged leaves' adjustment", cb));
  CheckAdjusted(plan, FinalLog(global));
  steps->push_back({"triangulate + adjust (slurm)", SecondsSince(t0), false});
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

namespace {

// A model that registered under half its leaf's frames, mapped again from the best-matched frame
// it left out; the model registering most is left in place and read into `result`.
void RetrySmallLeafModel(const MapBuildOptions& options, const LeafToRetry& leaf, int index, const MapBuildCallbacks& cb,
                         const LeafRetryStages& stages, MapBuildResult* result) {
  const auto registered = [&] { return static_cast<int>(result->map.keyframes.size()); };
  if (2 * registered() >= leaf.frames || options.fold_retries <= 0) return;
  const fs::path tries = leaf.dir / "small-tries";
  std::error_code ec;
  fs::remove_all(tries, ec);
  fs::create_directories(tries / "0");
  fs::create_directories(leaf.dir / "sparse");  // a mapper that registered nothing may have left none
  fs::rename(leaf.dir / "sparse", tries / "0" / "sparse");
  int best = 0, best_count = registered();
  MapBuildResult best_result = *result;
  const auto put_back_best = [&] {
    fs::remove_all(leaf.dir / "sparse", ec);
    fs::rename(tries / std::to_string(best) / "sparse", leaf.dir / "sparse");
    fs::remove_all(tries, ec);
    *result = best_result;
  };
  std::set<std::uint32_t> tried;
  for (int t = 1; t <= options.fold_retries && 2 * best_count < leaf.frames; ++t) {
    std::set<std::uint32_t> in_model;
    for (const map::Keyframe& k : best_result.map.keyframes) in_model.insert(k.colmap_image_id);
    const auto start = std::find_if(leaf.starts.begin(), leaf.starts.end(),
                                    [&](const auto& s) { return !in_model.count(s.first) && !tried.count(s.first); });
    if (start == leaf.starts.end()) break;
    tried.insert(start->first);
    if (cb.note)
      cb.note(leaf.name + ": COLMAP registered " + std::to_string(best_count) + " of its " + std::to_string(leaf.frames) +
              " frames: mapping again from " + start->second + ", try " + std::to_string(t) + " of " +
              std::to_string(options.fold_retries));
    fs::create_directories(leaf.dir / "sparse");
    int count = 0;
    try {
      stages.map_again(index, {"--Mapper.init_image_id1", std::to_string(start->first)});
      if (stages.read_and_check(index, result)) count = registered();
    } catch (const CancelledError&) {
      put_back_best();
      throw;
    } catch (const Error& e) {
      if (cb.note) cb.note(leaf.name + ": try " + std::to_string(t) + " failed: " + e.what());
    }
    fs::create_directories(tries / std::to_string(t));
    if (fs::exists(leaf.dir / "sparse")) fs::rename(leaf.dir / "sparse", tries / std::to_string(t) / "sparse");
    if (count > best_count) {
      best = t;
      best_count = count;
      best_result = *result;
    }
  }
  put_back_best();
  if (cb.note)
    cb.note(leaf.name + ": kept " + (best == 0 ? std::string("the first model") : "the model of try " + std::to_string(best)) +
            ", " + std::to_string(best_count) + " of " + std::to_string(leaf.frames) + " frames registered");
}

void RetryFoldedLeafModel(const MapBuildOptions& options, const LeafToRetry& leaf, int index, const MapBuildCallbacks& cb,
                          const LeafRetryStages& stages, MapBuildResult* result) {
  if (!Folded(result->check)) return;
  MapBuildCallbacks leaf_cb = cb;
  leaf_cb.note = [&](const std::string& note) {
    if (cb.note) cb.note(leaf.name + ": " + note);
  };
  FoldRetryStages retry;
  retry.map = [&](const std::vector<std::string>& extra) {
    fs::create_directories(leaf.dir / "sparse");
    stages.map_again(index, extra);
  };
  retry.read_model = [&] {
    if (!stages.read_and_check(index, result)) throw map::MapError(leaf.name + ": the mapper left no model");
  };
  retry.forget_map = retry.remember_map = [] {};
  RetryFoldedMap(options.fold_retries, leaf.dir, stages.log_of(index), leaf_cb, retry, result);
  if (Folded(result->check) && !options.keep_folded) {
    WriteMapCheck(result->check, leaf.dir / kMapCheckFileName);
    throw map::MapError(leaf.name + ": " + FoldRefusal(leaf.dir, *result));
  }
}

}  // namespace

void RetryLeafModels(const MapBuildOptions& options, const std::vector<LeafToRetry>& leaves, const MapBuildCallbacks& cb,
                     const LeafRetryStages& stages) {
  for (int i = 0; i < static_cast<int>(leaves.size()); ++i) {
    MapBuildResult result;
    stages.read_and_check(i, &result);  // no model: none of its frames registered
    RetrySmallLeafModel(options, leaves[static_cast<std::size_t>(i)], i, cb, stages, &result);
    RetryFoldedLeafModel(options, leaves[static_cast<std::size_t>(i)], i, cb, stages, &result);
  }
}

void MapInLeaves(const MapBuildOptions& options, const LeafMappingPaths& paths, const MapBuildCallbacks& cb,
                 std::vector<StageTiming>* steps) {
  const LeafPlan plan = PlanLeaves(options, paths, cb);
  if (options.engine == MapEngine::kSlurm) {
    RunOnSlurm(options, paths, plan, cb, steps);
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
