#include "mapping/pair_matching.h"


#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "base/atomic_file.h"
#include "map/descriptor_index.h"
#include "map/map.h"
#include "mapping/colmap_database.h"

namespace arview::mapping {

namespace fs = std::filesystem;

std::vector<ImagePair> ExhaustivePairs(int images) {
  std::vector<ImagePair> pairs;
  for (int i = 0; i < images; ++i)
    for (int j = i + 1; j < images; ++j) pairs.push_back({i, j});
  return pairs;
}

std::vector<ImagePair> SequentialPairs(int images, int overlap, bool quadratic) {
  std::vector<ImagePair> pairs;
  for (int i = 0; i < images; ++i) {
    std::vector<int> partners;
    for (int k = 1; k <= overlap && i + k < images; ++k) partners.push_back(i + k);
    if (quadratic) {
      for (int k = 0; k < overlap && k < 31; ++k) {
        const long long j = i + (1LL << k);
        if (j >= images) break;
        partners.push_back(static_cast<int>(j));
      }
    }
    std::sort(partners.begin(), partners.end());
    partners.erase(std::unique(partners.begin(), partners.end()), partners.end());
    for (int j : partners) pairs.push_back({i, j});
  }
  return pairs;
}

namespace {

// COLMAP's descriptors are unit vectors stored x512 as bytes: the angle between two of them
// from their Euclidean distance in byte units (|a-b| = 2 sin(angle/2) on the unit sphere).
// COLMAP's ratio and distance tests are on this angle.
float AngleOf(float byte_distance) {
  return 2.f * std::asin(std::min(1.f, byte_distance / (2.f * 512.f)));
}

// For each row of `from`, its best row in `to` when it passes the ratio and distance tests, else -1.
std::vector<int> BestMatchesOneWay(const cv::Mat& from, const map::DescriptorIndex& to, const PairMatchingOptions& o) {
  std::vector<int> best(static_cast<size_t>(from.rows), -1);
  if (from.rows == 0 || to.empty()) return best;
  const auto neighbours = to.Knn(from, 2);
  for (size_t r = 0; r < neighbours.size(); ++r) {
    const auto& n = neighbours[r];
    if (n.empty()) continue;
    const float first = AngleOf(n[0].distance);
    if (first > o.max_distance) continue;
    if (n.size() > 1 && first >= o.max_ratio * AngleOf(n[1].distance)) continue;
    best[r] = static_cast<int>(n[0].row);
  }
  return best;
}

// The rows of `from` that `chosen` names (each row once, ascending), for asking only about them.
std::vector<int> ChosenRows(const std::vector<int>& chosen) {
  std::vector<int> rows;
  for (int m : chosen)
    if (m >= 0) rows.push_back(m);
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

PairMatches MatchPair(const std::vector<cv::Mat>& descriptors, const std::vector<map::DescriptorIndex>& indices,
                      const ImagePair& pair, const PairMatchingOptions& o) {
  const auto a = static_cast<size_t>(pair.first), b = static_cast<size_t>(pair.second);
  const std::vector<int> forward = BestMatchesOneWay(descriptors[a], indices[b], o);
  PairMatches out{pair, {}};
  // The cross-check asks only about the rows of b that the forward search chose: each query's
  // answer does not depend on the others, so this is the full backward search's result for them
  // at a third to a half of its cost.
  std::vector<int> backward;
  if (o.cross_check) {
    const std::vector<int> chosen = ChosenRows(forward);
    // It keeps at most one match per chosen row: a pair already short of min_matches is done.
    if (static_cast<int>(chosen.size()) < o.min_matches) return out;
    cv::Mat asked(static_cast<int>(chosen.size()), descriptors[b].cols, descriptors[b].type());
    for (size_t i = 0; i < chosen.size(); ++i) descriptors[b].row(chosen[i]).copyTo(asked.row(static_cast<int>(i)));
    const std::vector<int> answers = BestMatchesOneWay(asked, indices[a], o);
    backward.assign(static_cast<size_t>(descriptors[b].rows), -1);
    for (size_t i = 0; i < chosen.size(); ++i) backward[static_cast<size_t>(chosen[i])] = answers[i];
  }
  for (size_t r = 0; r < forward.size(); ++r) {
    const int m = forward[r];
    if (m < 0) continue;
    if (o.cross_check && backward[static_cast<size_t>(m)] != static_cast<int>(r)) continue;
    out.matches.emplace_back(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(m));
  }
  if (static_cast<int>(out.matches.size()) < o.min_matches) out.matches.clear();
  return out;
}

}  // namespace

int Workers(int threads, size_t jobs) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int wanted = threads <= 0 ? cores : threads;
  return std::max(1, std::min<int>(wanted, static_cast<int>(std::max<size_t>(1, jobs))));
}

void ForEachInParallel(size_t count, int workers, const std::function<void(size_t)>& job,
                       const std::function<void(int, int)>& progress, const CancellationToken& cancel,
                       const std::string& what) {
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable changed;
  size_t done = 0;
  std::exception_ptr failure;
  auto work = [&] {
    for (size_t i; !stop.load() && (i = next++) < count;) {
      try {
        job(i);
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
      }
      const std::lock_guard lock(mutex);
      ++done;
      changed.notify_one();
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < workers; ++t) threads.emplace_back(work);
  {
    std::unique_lock lock(mutex);
    size_t reported = 0;
    while (done < count && !stop.load()) {
      changed.wait_for(lock, std::chrono::milliseconds(200));
      if (cancel.IsCancelled()) stop = true;
      if (progress && done != reported) {
        reported = done;
        const int d = static_cast<int>(done), total = static_cast<int>(count);
        lock.unlock();
        progress(d, total);
        lock.lock();
      }
    }
  }
  stop = true;
  for (auto& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
  cancel.ThrowIfCancelled(what);
}

std::vector<PairMatches> MatchImagePairs(const std::vector<cv::Mat>& descriptors, const std::vector<ImagePair>& pairs,
                                         const PairMatchingOptions& options,
                                         const std::function<void(int done, int total)>& progress,
                                         const CancellationToken& cancel) {
  for (const ImagePair& p : pairs) {
    if (p.first < 0 || p.second <= p.first || static_cast<size_t>(p.second) >= descriptors.size())
      throw map::MapError("image pair (" + std::to_string(p.first) + ", " + std::to_string(p.second) +
                          ") is not a pair of the " + std::to_string(descriptors.size()) + " images");
  }
  map::IndexParams params;
  params.kind = map::IndexKind::kKdTree;
  params.trees = options.trees;
  params.checks = options.checks;
  // One kd-tree per image, built once (COLMAP builds one per pair and direction).
  std::vector<map::DescriptorIndex> indices(descriptors.size());
  ForEachInParallel(
      descriptors.size(), Workers(options.threads, descriptors.size()),
      [&](size_t i) {
        if (descriptors[i].rows > 0) indices[i] = map::DescriptorIndex(descriptors[i], params);
      },
      {}, cancel, "matching stopped while its kd-trees were built");
  std::vector<PairMatches> result(pairs.size());
  ForEachInParallel(
      pairs.size(), Workers(options.threads, pairs.size()),
      [&](size_t i) { result[i] = MatchPair(descriptors, indices, pairs[i], options); }, progress, cancel,
      "matching stopped");
  return result;
}

void WriteMatchLists(const std::vector<std::string>& names, const std::vector<PairMatches>& matches,
                     const std::vector<fs::path>& parts) {
  if (parts.empty()) return;
  std::vector<std::string> texts(parts.size());
  // Dealt out by size: the next pair goes to the part with the fewest matches so far, so that
  // each verifying process gets about the same work.
  std::vector<size_t> load(parts.size(), 0);
  std::vector<size_t> order(matches.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return matches[a].matches.size() > matches[b].matches.size(); });
  std::vector<std::vector<size_t>> dealt(parts.size());
  for (size_t i : order) {
    if (matches[i].matches.empty()) continue;
    const size_t part = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[part] += matches[i].matches.size();
    dealt[part].push_back(i);
  }
  for (size_t part = 0; part < parts.size(); ++part) {
    std::sort(dealt[part].begin(), dealt[part].end());  // in pair order, as COLMAP would list them
    std::string& text = texts[part];
    for (size_t i : dealt[part]) {
      const PairMatches& m = matches[i];
      text += names.at(static_cast<size_t>(m.pair.first)) + " " + names.at(static_cast<size_t>(m.pair.second)) + "\n";
      for (const auto& [a, b] : m.matches) text += std::to_string(a) + " " + std::to_string(b) + "\n";
      text += "\n";
    }
    WriteFileAtomically(parts[part], text);
  }
}

void MergeVerifiedPairs(const fs::path& database, const fs::path& part) {
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite).ExecuteWithPart(part,
                      "BEGIN; INSERT OR REPLACE INTO main.matches SELECT * FROM part.matches; "
                      "INSERT OR REPLACE INTO main.two_view_geometries SELECT * FROM part.two_view_geometries; COMMIT;",
                      "add the verified pairs of " + part.string());
}

void MergeExtractedImages(const fs::path& database, const fs::path& part) {
  // The part's ids are moved past the database's, through ids from 2^30 up (COLMAP's image ids are
  // checked to lie in 0 .. 2^31 - 2), so that no two rows of the part ever share one; then its
  // rows are copied. Its camera must be the database's one camera (the same feature_extractor
  // command line).
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite).ExecuteWithPart(
      part,
      "BEGIN;"
      "UPDATE part.images SET image_id = image_id + 1073741824, camera_id = (SELECT camera_id FROM main.cameras);"
      "UPDATE part.keypoints SET image_id = image_id + 1073741824;"
      "UPDATE part.descriptors SET image_id = image_id + 1073741824;"
      "CREATE TEMP TABLE merge_offset AS SELECT IFNULL(MAX(image_id), 0) - 1073741824 AS value FROM main.images;"
      "UPDATE part.images SET image_id = image_id + (SELECT value FROM merge_offset);"
      "UPDATE part.keypoints SET image_id = image_id + (SELECT value FROM merge_offset);"
      "UPDATE part.descriptors SET image_id = image_id + (SELECT value FROM merge_offset);"
      "INSERT INTO main.images SELECT * FROM part.images;"
      "INSERT INTO main.keypoints SELECT * FROM part.keypoints;"
      "INSERT INTO main.descriptors SELECT * FROM part.descriptors;"
      "DROP TABLE temp.merge_offset; COMMIT;",
      "add the images extracted in " + part.string(),
      "SELECT (SELECT COUNT(*) FROM part.cameras) = 1 AND (SELECT COUNT(*) FROM main.cameras) = 1 AND"
      " (SELECT model || ' ' || width || ' ' || height || ' ' || hex(params) FROM part.cameras) ="
      " (SELECT model || ' ' || width || ' ' || height || ' ' || hex(params) FROM main.cameras)",
      "its camera is not the database's one camera");
}

}  // namespace arview::mapping
