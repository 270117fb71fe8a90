#include "map/descriptor_index.h"
#include "map/descriptor_size.h"

// OpenCV's copy of FLANN (cvflann), not libflann: libflann 1.9.2 shuffles the points before
// building each kd-tree with a std::random_device (flann/algorithms/kdtree_index.h), so its
// index, and every global match, changed from run to run whatever seed was set; cvflann
// shuffles with cv::theRNG(), which is seeded here.
#include <opencv2/flann.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <cstdlib>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "base/hash.h"

namespace arview::map {

namespace {

// cvflann's L2 for bytes: the same squared distance as cvflann::L2<unsigned char>, bit for bit
// (every partial sum is an integer below 2^24, exact in a float), computed 16 bytes at a time.
// cvflann's own converts each byte to float and tests for an early exit every 4 bytes, which
// the compiler cannot vectorise: the distance was most of the time of matching two frames. An
// early exit only ever rejected a candidate whose full distance is larger still, so every
// search returns what it returned with cvflann's.
struct L2Bytes {
  typedef cvflann::True is_kdtree_distance;
  typedef cvflann::True is_vector_space_distance;
  typedef unsigned char ElementType;
  typedef float ResultType;
  typedef ResultType CentersType;

  template <typename Iterator1, typename Iterator2>
  ResultType operator()(Iterator1 a, Iterator2 b, size_t size, ResultType /*worst_dist*/ = -1) const {
    if constexpr (IsBytes<Iterator1>() && IsBytes<Iterator2>()) {
      return static_cast<ResultType>(SquaredDistance(a, b, size));
    } else {  // a k-means centre (floats), or cvflann's zero iterator, against bytes
      ResultType result = 0;
      for (size_t i = 0; i < size; ++i) {
        const ResultType d = static_cast<ResultType>(a[i]) - static_cast<ResultType>(b[i]);
        result += d * d;
      }
      return result;
    }
  }

  template <typename Iterator>
  static constexpr bool IsBytes() {
    return std::is_pointer_v<Iterator> &&
           std::is_same_v<std::remove_cv_t<std::remove_pointer_t<Iterator>>, unsigned char>;
  }

  template <typename U, typename V>
  ResultType accum_dist(const U& a, const V& b, int) const {
    return static_cast<ResultType>((a - b) * (a - b));
  }

  static std::int32_t SquaredDistance(const unsigned char* a, const unsigned char* b, size_t size) {
    size_t i = 0;
    std::int32_t sum = 0;
#if defined(__SSE2__)
    const __m128i zero = _mm_setzero_si128();
    __m128i acc = zero;
    for (; i + 16 <= size; i += 16) {
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i));
      const __m128i low = _mm_sub_epi16(_mm_unpacklo_epi8(va, zero), _mm_unpacklo_epi8(vb, zero));
      const __m128i high = _mm_sub_epi16(_mm_unpackhi_epi8(va, zero), _mm_unpackhi_epi8(vb, zero));
      acc = _mm_add_epi32(acc, _mm_madd_epi16(low, low));
      acc = _mm_add_epi32(acc, _mm_madd_epi16(high, high));
    }
    alignas(16) std::int32_t lanes[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(lanes), acc);
    sum = lanes[0] + lanes[1] + lanes[2] + lanes[3];
#endif
    for (; i < size; ++i) {
      const std::int32_t d = static_cast<std::int32_t>(a[i]) - static_cast<std::int32_t>(b[i]);
      sum += d * d;
    }
    return sum;
  }
};

using FlannIndex = cvflann::Index<L2Bytes>;

void CheckDescriptorMatrix(const cv::Mat& m, const char* what) {
  if (m.type() != CV_8UC1 || m.cols != kDescriptorSize) {
    throw DescriptorIndexError(std::string("DescriptorIndex: ") + what +
                               " must be N x 128 CV_8U (got " + std::to_string(m.rows) + " x " +
                               std::to_string(m.cols) + ", type " + std::to_string(m.type()) + ")");
  }
}

cvflann::IndexParams ToFlann(const IndexParams& p) {
  switch (p.kind) {
    case IndexKind::kLinear:
      return cvflann::LinearIndexParams();
    case IndexKind::kKdTree:
      return cvflann::KDTreeIndexParams(std::max(1, p.trees));
    case IndexKind::kKMeans:
      return cvflann::KMeansIndexParams(std::max(2, p.branching), std::max(1, p.iterations));
  }
  throw DescriptorIndexError("DescriptorIndex: unknown index kind");
}

// cvflann's stride is in elements (bytes for uint8).
cvflann::Matrix<unsigned char> View(const cv::Mat& m) {
  return cvflann::Matrix<unsigned char>(const_cast<unsigned char*>(m.ptr<unsigned char>()),
                                        static_cast<size_t>(m.rows), kDescriptorSize, m.step[0]);
}

}  // namespace

struct DescriptorIndex::Impl {
  cv::Mat data;  // keeps the indexed rows alive
  std::unique_ptr<FlannIndex> index;
};

DescriptorIndex::DescriptorIndex() = default;
DescriptorIndex::~DescriptorIndex() = default;
DescriptorIndex::DescriptorIndex(DescriptorIndex&&) noexcept = default;
DescriptorIndex& DescriptorIndex::operator=(DescriptorIndex&&) noexcept = default;

DescriptorIndex::DescriptorIndex(const cv::Mat& descriptors, const IndexParams& params)
    : impl_(std::make_unique<Impl>()), params_(params) {
  CheckDescriptorMatrix(descriptors, "indexed descriptors");
  if (descriptors.rows == 0) throw DescriptorIndexError("DescriptorIndex: no descriptors to index");
  impl_->data = descriptors;
  // The kd-trees' shuffles draw from the thread's cv::theRNG(), the split dimensions from
  // std::rand(): both seeded, the thread's generator restored afterwards.
  const cv::RNG caller_rng = cv::theRNG();
  cvflann::seed_random(params.seed);
  std::srand(params.seed);
  impl_->index = std::make_unique<FlannIndex>(View(impl_->data), ToFlann(params));
  impl_->index->buildIndex();
  cv::theRNG() = caller_rng;
}

namespace {

namespace fs = std::filesystem;

// The cache file's name: the descriptors' bytes, the parameters that shape the index, and the
// versions of OpenCV and of this format, hashed.
std::string CacheKey(const cv::Mat& descriptors, const IndexParams& params) {
  Fnv1a h;
  for (int r = 0; r < descriptors.rows; ++r) h.Add(descriptors.ptr(r), descriptors.cols * descriptors.elemSize());
  for (int v : {static_cast<int>(params.kind), params.trees, params.branching, params.iterations, descriptors.rows,
                descriptors.cols, CV_VERSION_MAJOR, CV_VERSION_MINOR, CV_VERSION_REVISION, /*format*/ 1}) {
    h.AddValue(v);
  }
  h.AddValue(params.seed);
  char name[40];
  std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(h.hash));
  return name;
}

std::string ReadBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return in ? bytes.str() : std::string();
}

std::string ChecksumText(const std::string& bytes) {
  char text[40];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(Fnv1aOf(bytes.data(), bytes.size())));
  return text;
}

}  // namespace

DescriptorIndex DescriptorIndex::Cached(const cv::Mat& descriptors, const IndexParams& params,
                                        const std::filesystem::path& cache_folder, std::string* problem,
                                        bool* read_from_cache) {
  auto say = [problem](const std::string& text) {
    if (problem) *problem = text;
  };
  if (read_from_cache) *read_from_cache = false;
  if (cache_folder.empty() || params.kind == IndexKind::kLinear) return DescriptorIndex(descriptors, params);
  CheckDescriptorMatrix(descriptors, "indexed descriptors");
  if (descriptors.rows == 0) throw DescriptorIndexError("DescriptorIndex: no descriptors to index");
  const std::string key = CacheKey(descriptors, params);
  const fs::path file = cache_folder / (key + ".flann"), sum = cache_folder / (key + ".sum");
  std::error_code ec;
  if (fs::exists(file, ec) && fs::exists(sum, ec)) {
    // Verified before cvflann reads it: its loader trusts the sizes it finds in the file.
    const std::string bytes = ReadBytes(file);
    if (!bytes.empty() && ReadBytes(sum) == ChecksumText(bytes)) {
      try {
        DescriptorIndex index;
        index.impl_ = std::make_unique<Impl>();
        index.params_ = params;
        index.impl_->data = descriptors;
        index.impl_->index = std::make_unique<FlannIndex>(View(index.impl_->data), cvflann::SavedIndexParams(file.string()));
        if (read_from_cache) *read_from_cache = true;
        return index;
      } catch (const cv::Exception&) {
        // An index of another dataset or type: built again below.
      }
    }
    say("descriptor index cache " + file.string() + " did not verify; built again");
  }
  DescriptorIndex index(descriptors, params);
  // Written under temporary names and renamed, the checksum last: a reader never sees half a file.
  const std::string suffix = ".tmp" + std::to_string(::getpid());
  fs::create_directories(cache_folder, ec);
  try {
    index.impl_->index->save((file.string() + suffix));
    const std::string bytes = ReadBytes(file.string() + suffix);
    std::ofstream(sum.string() + suffix) << ChecksumText(bytes);
    fs::rename(file.string() + suffix, file, ec);
    if (!ec) fs::rename(sum.string() + suffix, sum, ec);
    if (ec) throw std::runtime_error(ec.message());
  } catch (const std::exception&) {
    fs::remove(file.string() + suffix, ec);
    fs::remove(sum.string() + suffix, ec);
    say("descriptor index built; it could not be cached in " + cache_folder.string());
  }
  return index;
}

std::size_t DescriptorIndex::size() const { return impl_ ? static_cast<std::size_t>(impl_->data.rows) : 0; }

std::vector<std::vector<Neighbor>> DescriptorIndex::Knn(const cv::Mat& queries, int k) const {
  CheckDescriptorMatrix(queries, "queries");
  std::vector<std::vector<Neighbor>> result(static_cast<size_t>(queries.rows));
  if (empty() || k <= 0 || queries.rows == 0) return result;
  const size_t kk = std::min(static_cast<size_t>(k), size());
  std::vector<int> index_rows(result.size() * kk, -1);
  std::vector<float> dist_rows(result.size() * kk, 0.f);
  cvflann::Matrix<int> indices(index_rows.data(), result.size(), kk);
  cvflann::Matrix<float> dists(dist_rows.data(), result.size(), kk);
  const cvflann::SearchParams search(params_.kind == IndexKind::kLinear ? cvflann::FLANN_CHECKS_UNLIMITED
                                                                         : std::max(1, params_.checks));
  impl_->index->knnSearch(View(queries), indices, dists, static_cast<int>(kk), search);
  for (size_t q = 0; q < result.size(); ++q) {
    auto& out = result[q];
    out.reserve(kk);
    for (size_t j = 0; j < kk; ++j) {
      // Padded with invalid indices when an approximate search found fewer than k.
      const int row = indices[q][j];
      if (row < 0 || static_cast<size_t>(row) >= size()) break;
      out.push_back({static_cast<std::uint32_t>(row), std::sqrt(std::max(0.f, dists[q][j]))});
    }
  }
  return result;
}

std::vector<Neighbor> DescriptorIndex::Knn(const std::uint8_t* descriptor, int k) const {
  const cv::Mat row(1, kDescriptorSize, CV_8UC1, const_cast<std::uint8_t*>(descriptor));
  return Knn(row, k).front();
}

std::vector<int> NearestNeighbourVotes(const DescriptorIndex& index, const std::vector<std::uint32_t>& owner_of_row,
                                       std::size_t owners, const cv::Mat& queries, double max_ratio) {
  std::vector<int> votes(owners, 0);
  if (queries.empty() || index.empty()) return votes;
  for (const auto& n : index.Knn(queries, 2))
    if (n.size() == 2 && n[0].distance < max_ratio * n[1].distance) ++votes[owner_of_row[n[0].row]];
  return votes;
}

}  // namespace arview::map
