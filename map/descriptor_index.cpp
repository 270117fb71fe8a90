#include "map/descriptor_index.h"

#include <flann/flann.hpp>

#include <cmath>
#include <string>

namespace arview::map {

namespace {

constexpr int kDescriptorSize = 128;
using FlannIndex = flann::Index<flann::L2<unsigned char>>;

void CheckDescriptorMatrix(const cv::Mat& m, const char* what) {
  if (m.type() != CV_8UC1 || m.cols != kDescriptorSize) {
    throw DescriptorIndexError(std::string("DescriptorIndex: ") + what +
                               " must be N x 128 CV_8U (got " + std::to_string(m.rows) + " x " +
                               std::to_string(m.cols) + ", type " + std::to_string(m.type()) + ")");
  }
}

flann::IndexParams ToFlann(const IndexParams& p) {
  switch (p.kind) {
    case IndexKind::kLinear:
      return flann::LinearIndexParams();
    case IndexKind::kKdTree:
      return flann::KDTreeIndexParams(std::max(1, p.trees));
    case IndexKind::kKMeans:
      return flann::KMeansIndexParams(std::max(2, p.branching), std::max(1, p.iterations));
  }
  throw DescriptorIndexError("DescriptorIndex: unknown index kind");
}

flann::Matrix<unsigned char> View(const cv::Mat& m) {
  return flann::Matrix<unsigned char>(const_cast<unsigned char*>(m.ptr<unsigned char>()),
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
  flann::seed_random(params.seed);
  impl_->index = std::make_unique<FlannIndex>(View(impl_->data), ToFlann(params));
  impl_->index->buildIndex();
}

std::size_t DescriptorIndex::size() const { return impl_ ? static_cast<std::size_t>(impl_->data.rows) : 0; }

std::vector<std::vector<Neighbor>> DescriptorIndex::Knn(const cv::Mat& queries, int k) const {
  CheckDescriptorMatrix(queries, "queries");
  std::vector<std::vector<Neighbor>> result(static_cast<size_t>(queries.rows));
  if (empty() || k <= 0 || queries.rows == 0) return result;
  const size_t kk = std::min(static_cast<size_t>(k), size());
  std::vector<std::vector<size_t>> indices;
  std::vector<std::vector<float>> dists;
  flann::SearchParams search(params_.kind == IndexKind::kLinear ? flann::FLANN_CHECKS_UNLIMITED
                                                                 : std::max(1, params_.checks));
  search.cores = std::max(1, params_.threads);
  impl_->index->knnSearch(View(queries), indices, dists, kk, search);
  for (size_t q = 0; q < result.size(); ++q) {
    auto& out = result[q];
    out.reserve(indices[q].size());
    for (size_t j = 0; j < indices[q].size(); ++j) {
      // FLANN pads with invalid indices when an approximate search found fewer than k.
      if (indices[q][j] >= size()) break;
      out.push_back({static_cast<std::uint32_t>(indices[q][j]), std::sqrt(std::max(0.f, dists[q][j]))});
    }
  }
  return result;
}

std::vector<Neighbor> DescriptorIndex::Knn(const std::uint8_t* descriptor, int k) const {
  const cv::Mat row(1, kDescriptorSize, CV_8UC1, const_cast<std::uint8_t*>(descriptor));
  return Knn(row, k).front();
}

}  // namespace arview::map
