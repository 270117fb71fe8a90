#include "map/descriptor_index.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <fstream>
#include <filesystem>

#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>

#include <cmath>
#include <random>

namespace arview::map {
namespace {

// Clustered random descriptors: like SIFT, many rows share structure, and each query is a
// perturbed copy of one row so that its true nearest neighbour is known to exist.
cv::Mat RandomDescriptors(int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(0, 120);
  cv::Mat m(rows, 128, CV_8UC1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 128; ++c) m.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(value(rng));
  }
  return m;
}

float BruteDistance(const cv::Mat& a, int ra, const cv::Mat& b, int rb) {
  return static_cast<float>(cv::norm(a.row(ra), b.row(rb), cv::NORM_L2));
}

TEST(DescriptorIndex, LinearIsExactAndSorted) {
  const cv::Mat data = RandomDescriptors(500, 1);
  const cv::Mat queries = RandomDescriptors(20, 2);
  const DescriptorIndex index(data, {.kind = IndexKind::kLinear});
  ASSERT_EQ(index.size(), 500u);
  const auto result = index.Knn(queries, 3);
  ASSERT_EQ(result.size(), 20u);
  for (int q = 0; q < queries.rows; ++q) {
    float best = 1e30f;
    int best_row = -1;
    for (int r = 0; r < data.rows; ++r) {
      const float d = BruteDistance(queries, q, data, r);
      if (d < best) best = d, best_row = r;
    }
    ASSERT_EQ(result[static_cast<size_t>(q)].size(), 3u);
    EXPECT_EQ(result[static_cast<size_t>(q)][0].row, static_cast<std::uint32_t>(best_row));
    EXPECT_NEAR(result[static_cast<size_t>(q)][0].distance, best, 1e-3f * best);
    EXPECT_LE(result[static_cast<size_t>(q)][0].distance, result[static_cast<size_t>(q)][1].distance);
    EXPECT_LE(result[static_cast<size_t>(q)][1].distance, result[static_cast<size_t>(q)][2].distance);
  }
}

// Random queries (no true copy in the index) make an approximate search depend on the trees:
// two indices built with the same seed answer the same, whatever the caller's cv::theRNG()
// holds (libflann, which shuffled with a std::random_device, did not).
TEST(DescriptorIndex, SameSeedSameNeighbours) {
  const cv::Mat data = RandomDescriptors(3000, 5);
  const cv::Mat queries = RandomDescriptors(300, 6);
  for (IndexKind kind : {IndexKind::kKdTree, IndexKind::kKMeans}) {
    const IndexParams params{.kind = kind, .checks = 16, .seed = 7};
    const auto first = DescriptorIndex(data, params).Knn(queries, 4);
    cv::theRNG() = cv::RNG(12345);
    const auto second = DescriptorIndex(data, params).Knn(queries, 4);
    for (size_t q = 0; q < first.size(); ++q) {
      ASSERT_EQ(first[q].size(), second[q].size()) << "kind " << static_cast<int>(kind) << " query " << q;
      for (size_t j = 0; j < first[q].size(); ++j)
        ASSERT_EQ(first[q][j].row, second[q][j].row) << "kind " << static_cast<int>(kind) << " query " << q;
    }
  }
}

// arview's byte distance answers exactly what cvflann's own L2<unsigned char> answers: the same
// trees (same seed), the same neighbours, the same distances, for kd-trees and k-means alike.
TEST(DescriptorIndex, TheByteDistanceAnswersAsCvflannsOwn) {
  const cv::Mat data = RandomDescriptors(3000, 11);
  const cv::Mat queries = RandomDescriptors(300, 12);
  for (IndexKind kind : {IndexKind::kKdTree, IndexKind::kKMeans, IndexKind::kLinear}) {
    const IndexParams params{.kind = kind, .checks = 32, .seed = 3};
    const auto ours = DescriptorIndex(data, params).Knn(queries, 2);
    const cv::RNG caller_rng = cv::theRNG();
    cvflann::seed_random(params.seed);
    std::srand(params.seed);
    const cvflann::IndexParams flann_params =
        kind == IndexKind::kKdTree   ? cvflann::IndexParams(cvflann::KDTreeIndexParams(params.trees))
        : kind == IndexKind::kKMeans ? cvflann::IndexParams(cvflann::KMeansIndexParams(params.branching, params.iterations))
                                     : cvflann::IndexParams(cvflann::LinearIndexParams());
    const cvflann::Matrix<unsigned char> view(data.data, static_cast<size_t>(data.rows), 128);
    cvflann::Index<cvflann::L2<unsigned char>> theirs(view, flann_params);
    theirs.buildIndex();
    cv::theRNG() = caller_rng;
    std::vector<int> rows(static_cast<size_t>(queries.rows) * 2);
    std::vector<float> squared(rows.size());
    cvflann::Matrix<int> row_view(rows.data(), static_cast<size_t>(queries.rows), 2);
    cvflann::Matrix<float> squared_view(squared.data(), static_cast<size_t>(queries.rows), 2);
    theirs.knnSearch(cvflann::Matrix<unsigned char>(queries.data, static_cast<size_t>(queries.rows), 128), row_view,
                     squared_view, 2,
                     cvflann::SearchParams(kind == IndexKind::kLinear ? cvflann::FLANN_CHECKS_UNLIMITED : params.checks));
    for (size_t q = 0; q < ours.size(); ++q) {
      ASSERT_EQ(ours[q].size(), 2u);
      for (size_t j = 0; j < 2; ++j) {
        EXPECT_EQ(static_cast<int>(ours[q][j].row), rows[q * 2 + j]) << "kind " << static_cast<int>(kind) << " query " << q;
        EXPECT_EQ(ours[q][j].distance, std::sqrt(squared[q * 2 + j])) << "kind " << static_cast<int>(kind) << " query " << q;
      }
    }
  }
}

TEST(DescriptorIndex, KdTreeFindsPerturbedCopies) {
  const cv::Mat data = RandomDescriptors(5000, 3);
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> pick(0, data.rows - 1), noise(-3, 3);
  cv::Mat queries(200, 128, CV_8UC1);
  std::vector<int> truth;
  for (int q = 0; q < queries.rows; ++q) {
    truth.push_back(pick(rng));
    for (int c = 0; c < 128; ++c) {
      queries.at<std::uint8_t>(q, c) =
          cv::saturate_cast<std::uint8_t>(data.at<std::uint8_t>(truth.back(), c) + noise(rng));
    }
  }
  for (IndexKind kind : {IndexKind::kKdTree, IndexKind::kKMeans}) {
    const DescriptorIndex index(data, {.kind = kind, .checks = 128});
    const auto result = index.Knn(queries, 2);
    int found = 0;
    for (size_t q = 0; q < truth.size(); ++q) found += !result[q].empty() && result[q][0].row == static_cast<std::uint32_t>(truth[q]);
    EXPECT_GE(found, 190) << "kind " << static_cast<int>(kind);
  }
}

TEST(DescriptorIndex, SingleQueryMatchesBatch) {
  const cv::Mat data = RandomDescriptors(300, 5);
  const DescriptorIndex index(data);
  const auto batch = index.Knn(data.row(7), 1);
  const auto single = index.Knn(data.ptr<std::uint8_t>(7), 1);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single[0].row, batch[0][0].row);
  EXPECT_EQ(single[0].row, 7u);
  EXPECT_FLOAT_EQ(single[0].distance, 0.f);
}

TEST(DescriptorIndex, KLargerThanTheIndexGivesEveryRow) {
  const cv::Mat data = RandomDescriptors(5, 6);
  const DescriptorIndex index(data, {.kind = IndexKind::kLinear});
  EXPECT_EQ(index.Knn(data.row(0), 10)[0].size(), 5u);
  EXPECT_TRUE(index.Knn(data.row(0), 0)[0].empty());
}

TEST(DescriptorIndex, RejectsWrongMatrices) {
  EXPECT_THROW(DescriptorIndex(cv::Mat(10, 64, CV_8UC1, cv::Scalar(0))), DescriptorIndexError);
  EXPECT_THROW(DescriptorIndex(cv::Mat(10, 128, CV_32FC1, cv::Scalar(0))), DescriptorIndexError);
  EXPECT_THROW(DescriptorIndex(cv::Mat(0, 128, CV_8UC1)), DescriptorIndexError);
  const DescriptorIndex index(RandomDescriptors(10, 7));
  EXPECT_THROW(index.Knn(cv::Mat(1, 128, CV_32FC1, cv::Scalar(0)), 1), DescriptorIndexError);
  const DescriptorIndex empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_TRUE(empty.Knn(RandomDescriptors(2, 8), 1)[0].empty());
}

void ExpectSameNeighbours(const std::vector<std::vector<Neighbor>>& a, const std::vector<std::vector<Neighbor>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t q = 0; q < a.size(); ++q) {
    ASSERT_EQ(a[q].size(), b[q].size()) << "query " << q;
    for (size_t j = 0; j < a[q].size(); ++j) {
      ASSERT_EQ(a[q][j].row, b[q][j].row) << "query " << q;
      ASSERT_EQ(a[q][j].distance, b[q][j].distance) << "query " << q;
    }
  }
}

// The cached index is the built one: read back, after a damaged file and without a writable
// folder, the neighbours are those of a fresh build.
TEST(DescriptorIndex, ACachedIndexIsReadBackAndADamagedOneBuiltAgain) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::temp_directory_path() / ("arview_index_cache_" + std::to_string(::getpid()));
  fs::remove_all(folder);
  for (IndexKind kind : {IndexKind::kKdTree, IndexKind::kKMeans}) {
    const cv::Mat data = RandomDescriptors(3000, 5);
    const cv::Mat queries = RandomDescriptors(300, 6);
    const IndexParams params{.kind = kind, .checks = 16, .seed = 7};
    const auto built = DescriptorIndex(data, params).Knn(queries, 4);
    std::string problem;
    bool read = true;
    ExpectSameNeighbours(DescriptorIndex::Cached(data, params, folder, &problem, &read).Knn(queries, 4), built);
    EXPECT_FALSE(read);
    EXPECT_EQ(problem, "");
    ExpectSameNeighbours(DescriptorIndex::Cached(data, params, folder, &problem, &read).Knn(queries, 4), built);
    EXPECT_TRUE(read) << "the second time, from the file";
    EXPECT_EQ(problem, "");
    // Another seed is another index: not read from this one's file.
    IndexParams other = params;
    other.seed = 8;
    DescriptorIndex::Cached(data, other, folder, &problem, &read);
    EXPECT_FALSE(read);
  }
  // Damage every cached index: each is rebuilt (and rewritten), with the same neighbours.
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".flann") continue;
    fs::resize_file(entry.path(), fs::file_size(entry.path()) / 2);
  }
  const cv::Mat data = RandomDescriptors(3000, 5), queries = RandomDescriptors(300, 6);
  const IndexParams params{.kind = IndexKind::kKdTree, .checks = 16, .seed = 7};
  std::string note;
  bool read = true;
  ExpectSameNeighbours(DescriptorIndex::Cached(data, params, folder, &note, &read).Knn(queries, 4),
                       DescriptorIndex(data, params).Knn(queries, 4));
  EXPECT_FALSE(read);
  EXPECT_NE(note.find("did not verify"), std::string::npos) << note;
  note.clear();
  DescriptorIndex::Cached(data, params, folder, &note, &read);
  EXPECT_TRUE(read) << "rewritten after the damaged one";
  EXPECT_EQ(note, "");
  // A folder that cannot be made (a file stands in its way): built, and said.
  const fs::path blocked = folder / "blocked";
  std::ofstream(blocked) << "a file";
  note.clear();
  ExpectSameNeighbours(DescriptorIndex::Cached(data, params, blocked / "cache", &note).Knn(queries, 4),
                       DescriptorIndex(data, params).Knn(queries, 4));
  EXPECT_NE(note.find("could not be cached"), std::string::npos) << note;
  fs::remove_all(folder);
}

}  // namespace
}  // namespace arview::map
