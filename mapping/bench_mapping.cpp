// bench_mapping: map load time and the descriptor index measurement behind the choice of index
// type (docs/mapping.md, "Descriptor index").
//
// Data: templeRing (../shared/data), imported, then two maps built with COLMAP on the first run
// and kept in $ARVIEW_BENCH_DIR (default /tmp/arview_bench_mapping): the even frames (the map
// that is indexed) and the odd frames (whose descriptors are the queries: features of frames
// the map has not seen, as the tracker will query). The first run takes a minute or two.
//
// Each index benchmark reports `recall`: the fraction of 2000 queries whose returned nearest row
// is the true nearest row (found by brute force); each iteration answers all 2000 queries (k = 2).
// Read the CPU column: on a shared machine the wall time includes waiting for a core.

#include <benchmark/benchmark.h>
#include <opencv2/flann.hpp>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>

#include "map/descriptor_index.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/venue_pairs.h"
#include "recordings/importers.h"
#include "tests/support/test_data.h"

namespace {

namespace fs = std::filesystem;
using namespace arview;

struct BenchData {
  fs::path map_dir;
  map::Map map;
  cv::Mat queries;                      // 2000 rows of the odd-frame map
  std::vector<std::uint32_t> truth;     // true nearest row of each query
};

fs::path BenchDir() {
  const char* env = std::getenv("ARVIEW_BENCH_DIR");
  return env && *env ? fs::path(env) : fs::temp_directory_path() / "arview_bench_mapping";
}

const BenchData& Data() {
  static std::unique_ptr<BenchData> data = [] {
    auto d = std::make_unique<BenchData>();
    const fs::path dir = BenchDir();
    const fs::path source = testing::SharedData("templeRing");
    if (!fs::exists(dir / "recording" / "frames.txt")) {
      recordings::ImportOptions io;
      io.overwrite = true;
      recordings::ImportMiddlebury(source, dir / "recording", io);
    }
    const recordings::Recording rec = recordings::LoadRecording(dir / "recording");
    mapping::MapBuildOptions options;
    options.frames_spec = "0-46:2";
    d->map = mapping::BuildMap(rec, dir / "even", options).map;  // re-uses finished stages
    d->map_dir = dir / "even";
    options.frames_spec = "1-45:2";
    const map::Map odd = mapping::BuildMap(rec, dir / "odd", options).map;
    const int n = std::min(2000, odd.descriptors.rows);
    const int step = std::max(1, odd.descriptors.rows / n);
    for (int r = 0; r < n; ++r) d->queries.push_back(odd.descriptors.row(r * step));
    const map::DescriptorIndex exact(d->map.descriptors, {.kind = map::IndexKind::kLinear});
    for (const auto& nn : exact.Knn(d->queries, 1)) d->truth.push_back(nn.at(0).row);
    std::cerr << "bench data: map " << d->map.descriptors.rows << " descriptors, " << d->queries.rows << " queries\n";
    return d;
  }();
  return *data;
}

void BM_LoadMap(benchmark::State& state) {
  const BenchData& d = Data();
  for (auto _ : state) {
    map::Map m = map::LoadMap(d.map_dir);
    benchmark::DoNotOptimize(m.points.data());
  }
  state.counters["descriptors"] = d.map.descriptors.rows;
  state.counters["file_MiB"] = static_cast<double>(fs::file_size(d.map_dir / map::kMapFileName)) / (1 << 20);
}
BENCHMARK(BM_LoadMap)->Unit(benchmark::kMillisecond);

// A venue's pairs across rooms (mapping/venue_pairs.h): templeRing's even and odd frames as two
// rooms, two sessions of one place, each frame's SIFT from its map's database (the quality
// preset's, up to 8,192 a frame); within rooms sequential (10), across from the descriptor index
// with the defaults (400 descriptors a frame, 5 neighbours). `across` counts the pairs found
// across; every odd frame's true neighbours are the even frames either side of it.
void BM_PairVenueFrames(benchmark::State& state) {
  const BenchData& d = Data();
  std::vector<cv::Mat> descriptors;
  std::vector<int> room_of;
  std::vector<int> frame_of;  // templeRing's frame number, from the image's name
  for (const auto& [folder, room] : {std::pair{"even", 0}, std::pair{"odd", 1}}) {
    std::ifstream list(BenchDir() / folder / "image_list.txt");
    std::vector<std::string> names;
    for (std::string name; std::getline(list, name);)
      if (!name.empty()) names.push_back(name);
    std::vector<cv::Mat> read = mapping::ReadImageDescriptors(BenchDir() / folder / "database.db", names);
    for (std::size_t i = 0; i < read.size(); ++i) {
      descriptors.push_back(std::move(read[i]));
      room_of.push_back(room);
      frame_of.push_back(std::stoi(fs::path(names[i]).stem().string()));
    }
  }
  mapping::CrossRoomOptions options;
  options.threads = static_cast<int>(state.range(0));
  mapping::VenuePairs pairs;
  for (auto _ : state) {
    pairs = mapping::PairVenueFrames(room_of, descriptors, [](int n) { return mapping::SequentialPairs(n, 10, false); },
                                     options);
    benchmark::DoNotOptimize(pairs.pairs.data());
  }
  state.counters["frames"] = static_cast<double>(descriptors.size());
  state.counters["across"] = static_cast<double>(pairs.pairs.size()) - pairs.within;
  // Of them, pairs of frames at most 4 apart on the ring of 47 (the views that overlap most).
  int near = 0;
  for (std::size_t k = static_cast<std::size_t>(pairs.within); k < pairs.pairs.size(); ++k) {
    const int gap = std::abs(frame_of[pairs.pairs[k].first] - frame_of[pairs.pairs[k].second]);
    near += std::min(gap, 47 - gap) <= 4;
  }
  state.counters["across_near"] = near;
  benchmark::DoNotOptimize(d.map.descriptors.rows);
}
// Wall time: the work is on the worker threads, the calling thread waits.
BENCHMARK(BM_PairVenueFrames)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

map::IndexParams Params(const benchmark::State& state) {
  map::IndexParams p;
  p.kind = static_cast<map::IndexKind>(state.range(0));
  p.trees = static_cast<int>(state.range(1));
  p.branching = static_cast<int>(state.range(1));
  p.checks = static_cast<int>(state.range(2));
  return p;
}

void BM_BuildIndex(benchmark::State& state) {
  const BenchData& d = Data();
  const map::IndexParams p = Params(state);
  for (auto _ : state) {
    map::DescriptorIndex index(d.map.descriptors, p);
    benchmark::DoNotOptimize(index.size());
  }
}

void BM_Knn(benchmark::State& state) {
  const BenchData& d = Data();
  const map::DescriptorIndex index(d.map.descriptors, Params(state));
  std::vector<std::vector<map::Neighbor>> result;
  for (auto _ : state) {
    result = index.Knn(d.queries, 2);
    benchmark::DoNotOptimize(result.data());
  }
  int hits = 0;
  for (size_t q = 0; q < result.size(); ++q) hits += !result[q].empty() && result[q][0].row == d.truth[q];
  state.counters["recall"] = static_cast<double>(hits) / static_cast<double>(result.size());
  state.counters["queries"] = d.queries.rows;  // time per query = CPU time / queries
}

// The same kd-tree search through cvflann's own L2<unsigned char> (what DescriptorIndex used
// before its byte distance, map/descriptor_index.cpp): the same trees (same seed) and answers,
// side by side in one run.
void BM_KnnCvflannL2(benchmark::State& state) {
  const BenchData& d = Data();
  const map::IndexParams p = Params(state);
  const cv::RNG caller_rng = cv::theRNG();
  cvflann::seed_random(p.seed);
  std::srand(p.seed);
  cvflann::Index<cvflann::L2<unsigned char>> index(
      cvflann::Matrix<unsigned char>(d.map.descriptors.data, static_cast<size_t>(d.map.descriptors.rows), 128),
      cvflann::KDTreeIndexParams(p.trees));
  index.buildIndex();
  cv::theRNG() = caller_rng;
  const size_t queries = static_cast<size_t>(d.queries.rows);
  std::vector<int> rows(queries * 2);
  std::vector<float> squared(queries * 2);
  cvflann::Matrix<int> row_view(rows.data(), queries, 2);
  cvflann::Matrix<float> squared_view(squared.data(), queries, 2);
  for (auto _ : state) {
    index.knnSearch(cvflann::Matrix<unsigned char>(d.queries.data, queries, 128), row_view, squared_view, 2,
                    cvflann::SearchParams(p.checks));
    benchmark::DoNotOptimize(rows.data());
  }
  int hits = 0;
  for (size_t q = 0; q < queries; ++q) hits += rows[q * 2] == static_cast<int>(d.truth[q]);
  state.counters["recall"] = static_cast<double>(hits) / static_cast<double>(queries);
  state.counters["queries"] = d.queries.rows;
}

// Args: kind (0 linear, 1 kd-tree, 2 k-means), trees or branching, checks.
void IndexGrid(benchmark::internal::Benchmark* b) {
  b->Args({0, 1, 0});
  for (int trees : {1, 4, 8}) {
    for (int checks : {16, 32, 64, 128, 256}) b->Args({1, trees, checks});
  }
  for (int checks : {16, 32, 64, 128, 256}) b->Args({2, 32, checks});
}

BENCHMARK(BM_BuildIndex)->Args({1, 4, 64})->Args({1, 8, 64})->Args({2, 32, 64})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Knn)->Apply(IndexGrid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_KnnCvflannL2)->Args({1, 4, 32})->Args({1, 4, 64})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
