#pragma once
// Nearest-neighbour search over the map's SIFT descriptors (Map::descriptors, N x 128 CV_8U in
// COLMAP's uint8 convention). The tracker queries it with its own frame's descriptors converted
// the same way (L1-normalise, square root, x512, round, clamp to 255).
//
// The index type was chosen by measurement (docs/map.md, "Descriptor index"): recall of the
// true nearest neighbour against query time on the templeRing map.

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include "base/error.h"

namespace arview::map {

struct DescriptorIndexError : Error {
  using Error::Error;
};

enum class IndexKind {
  kLinear,  // exact brute force (the reference for recall measurements)
  kKdTree,  // FLANN randomized kd-trees
  kKMeans,  // FLANN hierarchical k-means tree
};

struct IndexParams {
  IndexKind kind = IndexKind::kKdTree;
  int trees = 4;        // kd-trees: number of randomized trees
  int branching = 32;   // k-means: branching factor
  int iterations = 11;  // k-means: iterations per level
  int checks = 64;      // leaves visited per query (accuracy vs time); ignored by kLinear
  int threads = 1;      // unused: OpenCV's FLANN searches a batch on the calling thread
  unsigned seed = 0;    // the kd-trees' shuffles and split dimensions: same seed, same index
};

// One neighbour of a query: the row of Map::descriptors and the Euclidean (not squared)
// distance between the two uint8 descriptors, in descriptor units (0 .. 255*sqrt(128)).
struct Neighbor {
  std::uint32_t row = 0;
  float distance = 0;
};

class DescriptorIndex {
 public:
  DescriptorIndex();
  ~DescriptorIndex();
  DescriptorIndex(DescriptorIndex&&) noexcept;
  DescriptorIndex& operator=(DescriptorIndex&&) noexcept;

  // Builds the index over `descriptors` (N x 128, CV_8U, N > 0). The index keeps a reference-
  // counted header of the matrix (no copy): do not modify the rows while the index lives.
  // Throws DescriptorIndexError on a wrong type, shape or empty matrix.
  explicit DescriptorIndex(const cv::Mat& descriptors, const IndexParams& params = {});

  // The same index, kept in `cache_folder` and read back by later sessions on the same
  // descriptors and parameters: building it over a room's map took 1.8 s of `arview run`'s
  // start-up. The file is cvflann's saved index beside an FNV-1a checksum of it; one that does
  // not verify (cut, changed) is rebuilt and rewritten, and a folder that cannot be written
  // leaves the index built as usual. `problem` (optional) gets one line for the user when the
  // cache could not be used (did not verify, could not be written), else stays empty;
  // `read_from_cache` (optional) says whether the index came from the file.
  static DescriptorIndex Cached(const cv::Mat& descriptors, const IndexParams& params,
                                const std::filesystem::path& cache_folder, std::string* problem = nullptr,
                                bool* read_from_cache = nullptr);

  // For each row of `queries` (M x 128, CV_8U), its k nearest rows of the indexed matrix, best
  // first. result[q] has min(k, size()) entries (fewer only if an approximate index finds fewer).
  // Safe to call from several threads at once.
  std::vector<std::vector<Neighbor>> Knn(const cv::Mat& queries, int k) const;

  // The same for one descriptor (a 1 x 128 CV_8U row or 128 contiguous bytes).
  std::vector<Neighbor> Knn(const std::uint8_t* descriptor, int k) const;

  std::size_t size() const;
  bool empty() const { return size() == 0; }
  const IndexParams& params() const { return params_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  IndexParams params_;
};

// For each owner 0 .. owners-1 of the indexed rows (`owner_of_row`: a row's frame or keyframe),
// how many rows of `queries` have their nearest indexed row owned by it and pass the ratio test
// (nearest distance under `max_ratio` of the second nearest): the votes by which a frame finds
// the frames it looks most like (`map extend`'s old keyframes, a venue's frames of other rooms).
std::vector<int> NearestNeighbourVotes(const DescriptorIndex& index, const std::vector<std::uint32_t>& owner_of_row,
                                       std::size_t owners, const cv::Mat& queries, double max_ratio);

}  // namespace arview::map
