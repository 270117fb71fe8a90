#include "tracker/relocalizer.h"

#include "tracker/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <unordered_map>

namespace arview::tracker {

std::vector<MapMatch> MatchToMap(const Features& features, const map::Map& map,
                                 const map::DescriptorIndex& index, const MatchOptions& options) {
  std::vector<MapMatch> matches;
  if (features.descriptors.empty() || index.empty()) return matches;
  const auto neighbours = index.Knn(features.descriptors, options.knn);
  std::unordered_map<std::uint32_t, size_t> best_for_point;  // point → position in matches
  for (size_t q = 0; q < neighbours.size(); ++q) {
    const auto& nn = neighbours[q];
    if (nn.empty()) continue;
    const std::uint32_t best_point = map.descriptor_point[nn[0].row];
    float second = std::numeric_limits<float>::infinity();
    for (size_t j = 1; j < nn.size(); ++j) {
      if (map.descriptor_point[nn[j].row] != best_point) {
        second = nn[j].distance;
        break;
      }
    }
    // With fewer than k distinct points in reach, the last neighbour bounds the second best.
    if (!std::isfinite(second) && nn.size() == static_cast<size_t>(options.knn))
      second = nn.back().distance;
    if (std::isfinite(second) && nn[0].distance > options.ratio * second) continue;
    const MapMatch match{static_cast<int>(q), best_point, nn[0].distance};
    auto [it, inserted] = best_for_point.try_emplace(best_point, matches.size());
    if (inserted) matches.push_back(match);
    else if (match.distance < matches[it->second].distance) matches[it->second] = match;
  }
  return matches;
}

std::vector<int> KeyframesSeeingMost(const map::Map& map, const std::vector<std::uint32_t>& points, int count) {
  std::vector<char> wanted(map.points.size(), 0);
  for (std::uint32_t p : points)
    if (p < wanted.size()) wanted[p] = 1;
  std::vector<std::pair<int, int>> seen;  // (observed points, keyframe)
  for (size_t k = 0; k < map.keyframes.size(); ++k) {
    int n = 0;
    for (const map::KeyframeObservation& o : map.keyframes[k].observations) n += o.point < wanted.size() && wanted[o.point];
    if (n > 0) seen.emplace_back(n, static_cast<int>(k));
  }
  std::sort(seen.begin(), seen.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::vector<int> keyframes;
  for (size_t i = 0; i < seen.size() && static_cast<int>(i) < count; ++i) keyframes.push_back(seen[i].second);
  return keyframes;
}

void GatherCorrespondences(const Features& features, const map::Map& map,
                           const std::vector<MapMatch>& matches,
                           std::vector<Eigen::Vector2d>* pixels,
                           std::vector<Eigen::Vector3d>* points) {
  pixels->clear();
  points->clear();
  pixels->reserve(matches.size());
  points->reserve(matches.size());
  for (const auto& m : matches) {
    const cv::Point2f& p = features.keypoints[m.keypoint].pt;
    pixels->emplace_back(p.x, p.y);
    points->push_back(map.points[m.point].xyz);
  }
}

namespace {

// The pose's inliers as the flow follows them: each keypoint once, with the first point it was
// matched to among the inliers (a keypoint matched in several keyframes may name several).
Track2D3D FollowedInliers(const AbsolutePoseResult& pose, const std::vector<MapMatch>& matches,
                          const std::vector<Eigen::Vector2d>& pixels) {
  Track2D3D followed;
  std::set<int> keypoints;
  for (int i : pose.inliers) {
    if (!keypoints.insert(matches[i].keypoint).second) continue;
    followed.pixels.emplace_back(pixels[i].x(), pixels[i].y());
    followed.points.push_back(matches[i].point);
  }
  return followed;
}

bool SiftReducesFrame(const calib::Camera& camera, const RelocalizerOptions& options) {
  return WorkingResolution(camera, SiftLongSide(camera, options)).reduced();
}

}  // namespace

int SiftLongSide(const calib::Camera& camera, const RelocalizerOptions& options) {
  const int long_side = std::max(camera.width, camera.height);
  return long_side <= options.sift_own_size_up_to ? 0 : options.sift_long_side;
}

const FeatureOptions& ActiveFeatures(const calib::Camera& camera, const RelocalizerOptions& options) {
  return SiftReducesFrame(camera, options) ? options.reduced_features : options.features;
}

Features StrongestFeatures(const Features& features, int max_count) {
  if (max_count <= 0 || features.keypoints.size() <= static_cast<size_t>(max_count)) return features;
  std::vector<int> order(features.keypoints.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  // Ties broken by index, so that the selection does not depend on the sort's implementation.
  const auto stronger = [&](int a, int b) {
    const float ra = features.keypoints[a].response, rb = features.keypoints[b].response;
    return ra != rb ? ra > rb : a < b;
  };
  std::nth_element(order.begin(), order.begin() + max_count, order.end(), stronger);
  order.resize(static_cast<size_t>(max_count));
  std::sort(order.begin(), order.end());
  Features strongest;
  strongest.descriptors = cv::Mat(static_cast<int>(order.size()), features.descriptors.cols, features.descriptors.type());
  for (size_t i = 0; i < order.size(); ++i) {
    strongest.keypoints.push_back(features.keypoints[order[i]]);
    features.descriptors.row(order[i]).copyTo(strongest.descriptors.row(static_cast<int>(i)));
  }
  return strongest;
}

Relocalizer::Relocalizer(const map::Map& map, const calib::Camera& camera,
                         const map::DescriptorIndex& index, const RelocalizerOptions& options)
    : map_(map),
      camera_(camera),
      index_(index),
      options_(options),
      extractor_(ActiveFeatures(camera, options)),
      sift_resolution_(camera, SiftLongSide(camera, options)),
      reloc_resolution_(camera, RelocSiftLongSide(camera, options)) {}

int RelocSiftLongSide(const calib::Camera& camera, const RelocalizerOptions& options) {
  if (!SiftReducesFrame(camera, options)) return SiftLongSide(camera, options);
  return options.reloc_sift_long_side > 0 ? options.reloc_sift_long_side : options.sift_long_side;
}

Features Relocalizer::ExtractAt(const cv::Mat& gray, const SiftExtractor& extractor,
                                const WorkingResolution& resolution) const {
  // The reduction is defined for the camera's size only.
  const bool reduce = resolution.reduced() && gray.size() == camera_.Size();
  Features features = extractor.Extract(reduce ? resolution.Reduce(ToGray8(gray)) : gray);
  if (!reduce) return features;
  const auto size_scale = static_cast<float>(resolution.full_per_work());
  for (cv::KeyPoint& kp : features.keypoints) {
    const Eigen::Vector2d p = resolution.ToFull({kp.pt.x, kp.pt.y});
    kp.pt = cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
    kp.size *= size_scale;
  }
  return features;
}

RelocalizationResult Relocalizer::Relocalize(const cv::Mat& gray) const {
  const auto start = std::chrono::steady_clock::now();
  const Features features = ExtractOwn(gray);
  const double extract_ms = MillisecondsSince(start);
  RelocalizationResult result = Relocalize(features);
  result.extract_ms = extract_ms;
  return result;
}

RelocalizationResult Relocalizer::Relocalize(const Features& given) const {
  // Guided matching's features of a reduced frame: the strongest, as relocalization's own SIFT
  // would have kept (global matching's cost grows with the keypoints queried).
  const int max_count = options_.reduced_features.max_features;
  const bool limit = sift_resolution_.reduced() && max_count > 0 && given.keypoints.size() > static_cast<size_t>(max_count);
  const Features strongest = limit ? StrongestFeatures(given, max_count) : Features{};
  const Features& features = limit ? strongest : given;
  RelocalizationResult result;
  result.keypoints = static_cast<int>(features.keypoints.size());
  const auto match_start = std::chrono::steady_clock::now();
  const std::vector<MapMatch> matches = MatchToMap(features, map_, index_, options_.matching);
  result.match_ms = MillisecondsSince(match_start);
  result.matches = static_cast<int>(matches.size());
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  GatherCorrespondences(features, map_, matches, &pixels, &points);
  result.pose = EstimateAbsolutePose(camera_, pixels, points, options_.pose);
  if (result.pose.ok) {
    result.inliers = FollowedInliers(result.pose, matches, pixels);
    if (options_.keyframe_matching > 0) MatchKeyframesAndPose(features, matches, &result);
  }
  return result;
}

std::vector<MapMatch> MatchToKeyframes(const Features& features, const map::Map& map,
                                       const map::DescriptorIndex& index, const std::vector<int>& keyframes,
                                       int knn, double ratio) {
  std::vector<MapMatch> matches;
  // A map without each row's keyframe (one built by hand) has nothing to match keyframe by keyframe.
  const bool rows_have_keyframes = map.descriptor_keyframe.size() == static_cast<size_t>(map.descriptors.rows);
  if (features.descriptors.empty() || index.empty() || keyframes.empty() || !rows_have_keyframes) return matches;
  std::vector<int> slot(map.keyframes.size(), -1);
  for (size_t i = 0; i < keyframes.size(); ++i) slot[keyframes[i]] = static_cast<int>(i);
  const auto neighbours = index.Knn(features.descriptors, knn);
  const float inf = std::numeric_limits<float>::infinity();
  // Per chosen keyframe, for the keypoint at hand: its nearest row and the distance to its second
  // (the last neighbour bounds a second that is not among the k).
  std::vector<std::pair<int, float>> best(keyframes.size());
  std::vector<float> second(keyframes.size());
  std::vector<char> seen_second(keyframes.size());
  for (size_t q = 0; q < neighbours.size(); ++q) {
    const auto& nn = neighbours[q];
    if (nn.empty()) continue;
    std::fill(best.begin(), best.end(), std::pair<int, float>{-1, inf});
    std::fill(second.begin(), second.end(), nn.size() == static_cast<size_t>(knn) ? nn.back().distance : inf);
    std::fill(seen_second.begin(), seen_second.end(), 0);
    for (const map::Neighbor& n : nn) {
      const int k = slot[map.descriptor_keyframe[n.row]];
      if (k < 0) continue;
      if (best[k].first < 0) best[k] = {static_cast<int>(n.row), n.distance};
      else if (!seen_second[k]) { second[k] = n.distance; seen_second[k] = 1; }
    }
    for (size_t k = 0; k < keyframes.size(); ++k) {
      if (best[k].first < 0 || !(best[k].second <= ratio * second[k])) continue;
      matches.push_back({static_cast<int>(q), map.descriptor_point[best[k].first], best[k].second});
    }
  }
  return matches;
}

void Relocalizer::MatchKeyframesAndPose(const Features& features, const std::vector<MapMatch>& global,
                                        RelocalizationResult* result) const {
  const auto start = std::chrono::steady_clock::now();
  std::vector<MapMatch> matches = global;
  std::set<std::pair<int, std::uint32_t>> known;  // (keypoint, point)
  for (const MapMatch& m : global) known.emplace(m.keypoint, m.point);
  const std::vector<int> keyframes = KeyframesSeeingMost(map_, result->inliers.points, options_.keyframe_matching);
  for (const MapMatch& m : MatchToKeyframes(features, map_, index_, keyframes, options_.keyframe_knn, options_.matching.ratio))
    if (known.emplace(m.keypoint, m.point).second) matches.push_back(m);
  result->match_ms += MillisecondsSince(start);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  GatherCorrespondences(features, map_, matches, &pixels, &points);
  AbsolutePoseResult pose = EstimateAbsolutePose(camera_, pixels, points, options_.pose);
  // The frame's time is both poses'.
  result->pose.stats.ransac_ms += pose.stats.ransac_ms;
  result->pose.stats.refine_ms += pose.stats.refine_ms;
  if (!pose.ok) return;  // the first pose stands
  pose.stats.ransac_ms = result->pose.stats.ransac_ms;
  pose.stats.refine_ms = result->pose.stats.refine_ms;
  result->matches = static_cast<int>(matches.size());
  result->inliers = FollowedInliers(pose, matches, pixels);
  result->pose = std::move(pose);
}

}  // namespace arview::tracker
