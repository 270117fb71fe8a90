// The match stage when arview matches (MatchEngine::kArview): the pairs matched here with a
// kd-tree per frame (mapping/pair_matching.h), then verified by COLMAP's matches_importer in
// several processes at once, each on a copy of the database merged back after; and what decides
// the matches, for the stage records. Apart from the build's sequence (MapBuild,
// mapping/colmap_pipeline.cpp); declared in mapping/map_build_stages.h.

#include "mapping/map_build_stages.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "base/atomic_file.h"
#include "map/map.h"
#include "mapping/colmap_model.h"

namespace arview::mapping {

namespace fs = std::filesystem;

bool NamesFitAMatchList(const std::vector<std::string>& names) {
  return std::none_of(names.begin(), names.end(), [](const std::string& name) {
    return name.empty() || name.find_first_of(" \t\r\n") != std::string::npos;
  });
}

bool VenuePairsWanted(const MapBuildOptions& options, int frames) {
  return options.rooms.size() >= 2 && options.cross_rooms.neighbours > 0 && !ExhaustiveMatchingWanted(options, frames);
}

std::vector<int> RoomOfEachImage(const MapBuildOptions& options, const std::vector<std::string>& names,
                                 const FrameLookup& lookup) {
  if (options.rooms.size() < 2) return {};
  std::vector<int> room_of;
  for (const std::string& name : names) {
    const auto frame = lookup.find(name);
    const int index = frame == lookup.end() ? -1 : frame->second.frame_index;
    const auto room = std::find_if(options.rooms.begin(), options.rooms.end(),
                                   [&](const VenueRoom& r) { return r.Holds(index); });
    room_of.push_back(room == options.rooms.end() ? -1 : static_cast<int>(room - options.rooms.begin()));
  }
  return room_of;
}

std::vector<ImagePair> PairsToMatch(const MapBuildOptions& options, const std::vector<std::string>& names,
                                    const FrameLookup& lookup, const fs::path& database, const MapBuildCallbacks& cb,
                                    const std::vector<cv::Mat>* descriptors) {
  const int frames = static_cast<int>(names.size());
  if (!VenuePairsWanted(options, frames)) {
    return ExhaustiveMatchingWanted(options, frames)
               ? ExhaustivePairs(frames)
               : SequentialPairs(frames, options.sequential_overlap, options.quadratic_overlap);
  }
  std::vector<cv::Mat> read;
  if (descriptors == nullptr) {
    read = ReadImageDescriptors(database, names, options.cancel);
    descriptors = &read;
  }
  CrossRoomOptions cross = options.cross_rooms;
  cross.threads = options.threads;
  const VenuePairs pairs = PairVenueFrames(
      RoomOfEachImage(options, names, lookup), *descriptors,
      [&](int n) { return SequentialPairs(n, options.sequential_overlap, options.quadratic_overlap); }, cross,
      [&](int done, int total) {
        if (cb.progress) cb.progress("pair rooms", done, total);
      },
      options.cancel);
  std::vector<std::string> room_names;
  for (const VenueRoom& r : options.rooms) room_names.push_back(r.name);
  if (cb.note) cb.note("venue: " + pairs.Describe(room_names));
  return pairs.pairs;
}

namespace {

int VerifyingProcesses(const MapBuildOptions& options) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, options.threads <= 0 ? cores : options.threads);
}

// "exhaustive" or "sequential 10 quadratic": which pairs are matched, for the stage records; a
// venue's rooms and its pairs across them too.
std::string PairsWanted(const MapBuildOptions& options, int frames) {
  if (ExhaustiveMatchingWanted(options, frames)) return "exhaustive";
  std::string wanted = "sequential " + std::to_string(options.sequential_overlap) + (options.quadratic_overlap ? " quadratic" : "");
  if (!VenuePairsWanted(options, frames)) return wanted;
  const CrossRoomOptions& c = options.cross_rooms;
  wanted += " within rooms";
  for (const VenueRoom& r : options.rooms) wanted += " " + std::to_string(r.first_frame) + "+" + std::to_string(r.frames);
  return wanted + "; across " + std::to_string(c.neighbours) + " neighbours, " + std::to_string(c.descriptors_per_frame) +
         " descriptors, " + std::to_string(c.min_votes) + " votes, ratio " + FormatParams({c.max_ratio});
}

}  // namespace

std::string ArviewMatchInputs(const MapBuildOptions& options, int frames) {
  const PairMatchingOptions& m = options.pair_matching;
  std::ostringstream ss;
  ss << "arview pair matching\n" << PairsWanted(options, frames) << "\nratio " << m.max_ratio << " distance " << m.max_distance << " cross " << m.cross_check << " trees "
     << m.trees << " checks " << m.checks << " at least " << m.min_matches << "\nmatches_importer raw\n";
  return ss.str();
}

std::string ListedPairsMatchInputs(const MapBuildOptions& options, int frames) {
  return "COLMAP matches_importer on listed pairs\n" + PairsWanted(options, frames) + "\nthreads " +
         std::to_string(options.threads) + "\n";
}

std::string SlurmMatchInputs(const MapBuildOptions& options, int frames) {
  return "COLMAP pair matching in Slurm jobs\n" + PairsWanted(options, frames) + "\nthreads " +
         std::to_string(options.threads) + "\n";
}

namespace {

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

}  // namespace

void MatchWithArview(ColmapRunner& colmap, const fs::path& database, const fs::path& out_dir,
                     const std::vector<std::string>& names, const FrameLookup& lookup, const MapBuildOptions& options,
                     const MapBuildCallbacks& cb, std::vector<StageTiming>* timings) {
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<cv::Mat> descriptors = ReadImageDescriptors(database, names, options.cancel);
  const std::vector<ImagePair> pairs = PairsToMatch(options, names, lookup, database, cb, &descriptors);
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

void MatchListedPairsWithColmap(ColmapRunner& colmap, const fs::path& database, const fs::path& out_dir,
                                const std::vector<std::string>& names, const FrameLookup& lookup,
                                const MapBuildOptions& options, const MapBuildCallbacks& cb) {
  const std::vector<ImagePair> pairs = PairsToMatch(options, names, lookup, database, cb);
  std::string text;
  for (const ImagePair& p : pairs)
    text += names.at(static_cast<std::size_t>(p.first)) + " " + names.at(static_cast<std::size_t>(p.second)) + "\n";
  const fs::path list = out_dir / "venue-pairs.txt";
  WriteFileAtomically(list, text);
  // Progress: COLMAP prints "Matching block [i/N]" every 1,225 pairs (matches_importer has no
  // option for the block's size).
  try {
    colmap.Run("match",
               {"matches_importer", "--database_path", database.string(), "--match_list_path", list.string(),
                "--match_type", "pairs", "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
                std::to_string(options.threads)},
               static_cast<int>(names.size()));
  } catch (...) {
    std::error_code ec;
    fs::remove(list, ec);
    throw;
  }
  std::error_code ec;
  fs::remove(list, ec);
}

}  // namespace arview::mapping
