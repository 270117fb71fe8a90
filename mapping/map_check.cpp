// The map's self-check (see map_check.h for what and why).

#include "mapping/map_check.h"

#include "base/library_errors.h"

#include <Eigen/SVD>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <unordered_map>

#include "base/atomic_file.h"
#include "base/input_guard.h"
#include "base/stats.h"

namespace arview::mapping {

std::string Percent(double fraction) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(fraction < 0.1 ? 1 : 0) << 100 * fraction << "%";
  return s.str();
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string OffFrameList(const MapCheck& check) {
  constexpr std::size_t kShown = 12;
  std::string list;
  for (std::size_t i = 0; i < check.disagreeing_frames.size() && i < kShown; ++i)
    list += (i ? ", " : "") + std::to_string(check.disagreeing_frames[i]);
  if (check.disagreeing_frames.size() > kShown) list += ", ...";
  return list;
}

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Keypoints of one image in a grid of `radius`-sized cells, for "is one within radius of p".
class KeypointGrid {
 public:
  KeypointGrid(const std::vector<Eigen::Vector2f>& points, double radius) : points_(points), radius_(radius) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[Key(Cell(points[i].x()), Cell(points[i].y()))].push_back(i);
  }
  bool AnyWithin(const Eigen::Vector2f& p) const {
    const long cx = Cell(p.x()), cy = Cell(p.y());
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(Key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (std::size_t i : it->second)
          if ((points_[i] - p).norm() <= radius_) return true;
      }
    return false;
  }

 private:
  long Cell(float v) const { return static_cast<long>(std::floor(v / radius_)); }
  static std::uint64_t Key(long x, long y) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
  }
  const std::vector<Eigen::Vector2f>& points_;
  double radius_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

// Median pixel motion of the map points seen by both keyframes (nothing when none is shared).
std::optional<double> PointMotion(const map::Keyframe& a, const map::Keyframe& b) {
  std::unordered_map<std::uint32_t, Eigen::Vector2f> in_a;
  for (const auto& o : a.observations) in_a.emplace(o.point, o.pixel);
  std::vector<double> motion;
  for (const auto& o : b.observations)
    if (const auto it = in_a.find(o.point); it != in_a.end()) motion.push_back((o.pixel - it->second).norm());
  if (motion.empty()) return std::nullopt;
  return Median(motion);
}

double StillFraction(const std::vector<Eigen::Vector2f>& a, const std::vector<Eigen::Vector2f>& b, double radius) {
  if (a.empty()) return 0;
  const KeypointGrid grid(b, radius);
  const auto still = std::count_if(a.begin(), a.end(), [&](const Eigen::Vector2f& p) { return grid.AnyWithin(p); });
  return static_cast<double>(still) / static_cast<double>(a.size());
}

// Per point, the widest angle between two of the rays from the keyframes that see it.
double MedianTriangulationDeg(const map::Map& map, const std::vector<Eigen::Vector3d>& centres) {
  std::vector<double> angles;
  angles.reserve(map.points.size());
  std::vector<Eigen::Vector3d> rays;
  for (const map::MapPoint& p : map.points) {
    rays.clear();
    for (std::uint32_t r = p.first_descriptor; r < p.first_descriptor + p.descriptor_count; ++r) {
      if (r >= map.descriptor_keyframe.size()) break;
      const Eigen::Vector3d ray = p.xyz - centres[map.descriptor_keyframe[r]];
      if (ray.norm() > 0) rays.push_back(ray.normalized());
    }
    double min_cos = 1;  // of the widest pair
    for (std::size_t i = 0; i < rays.size(); ++i)
      for (std::size_t j = i + 1; j < rays.size(); ++j) min_cos = std::min(min_cos, rays[i].dot(rays[j]));
    angles.push_back(std::acos(std::clamp(min_cos, -1.0, 1.0)) * 180.0 / M_PI);
  }
  return Median(angles);
}

// The median depth (along the optical axis) of the points each keyframe sees; median of those.
double SceneDepth(const map::Map& map) {
  std::vector<double> per_keyframe;
  for (const map::Keyframe& k : map.keyframes) {
    std::vector<double> depths;
    for (const auto& o : k.observations) {
      if (o.point >= map.points.size()) continue;
      const double z = k.pose.ToCamera(map.points[o.point].xyz).z();
      if (z > 0) depths.push_back(z);
    }
    if (!depths.empty()) per_keyframe.push_back(Median(depths));
  }
  return Median(per_keyframe);
}

// One keyframe pair's rotation in the map against its own two-view geometry.
struct PairDisagreement {
  int a = 0, b = 0;  // indices into Map::keyframes
  double deg = 0;
  bool fitted = false;  // the map's relative pose fits the pair's matches (MapCheckLimits::two_view_fit_px)
};

// The median Sampson distance of matched normalised points under `essential`, in pixels of focal
// length `focal_px` (the first-order distance of each match from its epipolar lines). Nothing for a
// zero matrix (two keyframes at one place) or no matches.
std::optional<double> MedianSampsonPx(const Eigen::Matrix3d& essential, const std::vector<Eigen::Vector3d>& in_a,
                                      const std::vector<Eigen::Vector3d>& in_b, double focal_px) {
  if (in_a.empty() || essential.norm() < 1e-12) return std::nullopt;
  std::vector<double> distances;
  distances.reserve(in_a.size());
  for (std::size_t i = 0; i < in_a.size(); ++i) {
    const Eigen::Vector3d line_b = essential * in_a[i], line_a = essential.transpose() * in_b[i];
    const double gradient = line_b.head<2>().squaredNorm() + line_a.head<2>().squaredNorm();
    if (gradient <= 0) continue;
    distances.push_back(std::abs(in_b[i].dot(line_b)) / std::sqrt(gradient) * focal_px);
  }
  if (distances.empty()) return std::nullopt;
  return Median(distances);
}

// Whether the map's relative pose of the pair fits its verified matches as well as the pair's own
// essential matrix does, or within limits.two_view_fit_px (MapCheckLimits). False when the matches,
// the keypoints or the camera are not known.
bool MapPoseFitsTheMatches(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                           const TwoViewGeometry& g, const MapCheckLimits& limits) {
  const auto a = static_cast<std::size_t>(g.keyframe_a), b = static_cast<std::size_t>(g.keyframe_b);
  if (g.matches.empty() || map.camera.fx <= 0 || map.camera.fy <= 0 || a >= keypoints.size() || b >= keypoints.size())
    return false;
  std::vector<Eigen::Vector3d> in_a, in_b;
  in_a.reserve(g.matches.size());
  in_b.reserve(g.matches.size());
  for (const auto& [index_a, index_b] : g.matches) {
    if (index_a >= keypoints[a].size() || index_b >= keypoints[b].size()) return false;  // not this model's keypoints
    in_a.push_back(map.camera.PixelToNormalized(keypoints[a][index_a].cast<double>()).homogeneous());
    in_b.push_back(map.camera.PixelToNormalized(keypoints[b][index_b].cast<double>()).homogeneous());
  }
  const double focal_px = 0.5 * (map.camera.fx + map.camera.fy);
  const std::optional<double> map_fit =
      MedianSampsonPx(EssentialBetween(map.keyframes[a].pose, map.keyframes[b].pose), in_a, in_b, focal_px);
  const std::optional<double> own_fit = MedianSampsonPx(g.essential, in_a, in_b, focal_px);
  return map_fit && *map_fit <= std::max(limits.two_view_fit_px, own_fit.value_or(0));
}

// The pairs matched well enough to be compared (limits.two_view_min_inliers), with their
// disagreement in degrees and whether the map's pose fits their matches.
std::vector<PairDisagreement> ComparablePairs(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                                              const std::vector<TwoViewGeometry>& two_view, const MapCheckLimits& limits) {
  const int n = static_cast<int>(map.keyframes.size());
  std::vector<PairDisagreement> pairs;
  for (const TwoViewGeometry& g : two_view) {
    if (g.inliers < limits.two_view_min_inliers || g.keyframe_a < 0 || g.keyframe_b < 0 || g.keyframe_a >= n ||
        g.keyframe_b >= n || g.keyframe_a == g.keyframe_b)
      continue;
    const Eigen::Matrix3d rotation_ab = map.keyframes[g.keyframe_b].pose.R() * map.keyframes[g.keyframe_a].pose.R().transpose();
    if (const std::optional<double> off_deg = RotationDisagreementDeg(g.essential, rotation_ab))
      pairs.push_back({g.keyframe_a, g.keyframe_b, *off_deg, MapPoseFitsTheMatches(map, keypoints, g, limits)});
  }
  return pairs;
}

// The map's camera rotations against the pairs' two-view geometry (map_check.h): the fraction of
// pairs that disagree by more than two_view_max_disagreement_deg, and the keyframes whose own
// pairs disagree by more than the map's typical pair does. A pair whose matches the map's pose fits
// counts as agreeing (0 degrees) in both; the map's median pair, which sets the keyframes' limit,
// stays the essential matrices' own.
void CompareTwoViewRotations(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                             const std::vector<TwoViewGeometry>& two_view, const MapCheckLimits& limits, MapCheck& c) {
  const std::vector<PairDisagreement> pairs = ComparablePairs(map, keypoints, two_view, limits);
  std::vector<std::vector<double>> per_keyframe(map.keyframes.size());
  std::vector<double> all;
  int disagree = 0;
  for (const PairDisagreement& p : pairs) {
    const double judged_deg = p.fitted ? 0.0 : p.deg;
    c.fitted_pairs += p.fitted;
    disagree += judged_deg > limits.two_view_max_disagreement_deg;
    all.push_back(p.deg);
    per_keyframe[p.a].push_back(judged_deg);
    per_keyframe[p.b].push_back(judged_deg);
  }
  c.two_view_pairs = static_cast<int>(pairs.size());
  c.disagreeing_fraction = pairs.empty() ? 0 : static_cast<double>(disagree) / static_cast<double>(pairs.size());
  c.median_disagreement_deg = Median(all);
  c.keyframe_off_deg = std::clamp(limits.keyframe_off_factor * c.median_disagreement_deg, limits.keyframe_min_off_deg,
                                  std::max(limits.keyframe_min_off_deg, limits.two_view_max_disagreement_deg));
  c.keyframe_agreeing_pairs.assign(map.keyframes.size(), 0);
  int previous_off_index = -2;  // of the last keyframe found off
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const std::vector<double>& own = per_keyframe[k];
    if (own.empty()) continue;
    const double own_median_deg = Median(own);
    c.keyframe_agreeing_pairs[k] =
        static_cast<int>(std::count_if(own.begin(), own.end(), [&](double d) { return d <= c.keyframe_off_deg; }));
    if (static_cast<int>(own.size()) >= limits.keyframe_min_pairs && own_median_deg > c.keyframe_off_deg) {
      c.disagreeing_frames.push_back(map.keyframes[k].frame_index);
      c.off_neighbours += previous_off_index == static_cast<int>(k) - 1;
      previous_off_index = static_cast<int>(k);
    }
  }
}

// What a fold looks like, in the map's own figures, and what to do.
std::string FoldWarning(const MapCheck& c, const MapCheckLimits& limits) {
  const std::string where = OffFrameList(c);
  std::string what = "its camera rotations differ from it by more than " +
                     Fixed(limits.two_view_max_disagreement_deg, 0) + " degrees in " + Percent(c.disagreeing_fraction) +
                     " of " + std::to_string(c.two_view_pairs) + " well-matched keyframe pairs";
  if (!where.empty())
    what += "; the pairs of frames " + where + " disagree by a median of more than " + Fixed(c.keyframe_off_deg, 1) +
            " degrees, where the map's median pair disagrees by " + Fixed(c.median_disagreement_deg, 1);
  return "disagrees with the frames' own two-view geometry (" + what +
         "): COLMAP registered part of the path wrongly (a fold, seen when the first frames film a flat scene), "
         "and tracking there will be off. Map other frames (--frames), or film that part again moving the camera "
         "sideways (arview map maps such a model again from another start, --fold-retries, and refuses it "
         "unless --keep-folded)";
}

void AddWarnings(MapCheck& c, const MapCheckLimits& limits) {
  if (c.moving_pairs > 0 && c.still_fraction > limits.max_still_fraction)
    c.warnings.push_back(
        "looks like a still camera filming a moving object: " + Percent(c.still_fraction) +
        " of each frame's features stay in place (within " + Fixed(limits.still_radius_px, 1) +
        " px) while the map's points move between the frames, so the camera path is the object's motion, not the "
        "camera's. Record again moving the camera through a still scene, with moving things out of view");
  if (c.extent_ratio < limits.min_extent_ratio)
    c.warnings.push_back("has a camera path spanning " + Percent(c.extent_ratio) +
                         " of the scene's depth: looks like a still camera, or one that only turned, and the map's "
                         "depth is guessed. Record again moving the camera sideways by a tenth of its distance to "
                         "the scene or more");
  if (c.extent_ratio > limits.max_extent_ratio)
    c.warnings.push_back("has a camera path spanning " + Fixed(c.extent_ratio, 0) +
                         " times the scene's depth: its points sit next to the cameras that see them, a model "
                         "COLMAP let collapse, whose poses are wrong. Map again with --matcher exhaustive, or the "
                         "recording in shorter parts (--frames)");
  if (c.median_triangulation_deg < limits.min_triangulation_deg)
    c.warnings.push_back("has its points triangulated from rays a median " + Fixed(c.median_triangulation_deg, 2) +
                         " degrees apart: their depth is poorly determined. Move the camera further between the "
                         "frames (or give COLMAP more widely spaced frames with --frames)");
  if (c.explained_fraction < limits.min_explained_fraction)
    c.warnings.push_back("explains only " + Percent(c.explained_fraction) +
                         " of the frames' features: the scene changed while it was filmed, or most of what was "
                         "filmed moved. Record a still scene");
  if (Folded(c, limits)) c.warnings.push_back(FoldWarning(c, limits));
}

}  // namespace

bool Folded(const MapCheck& check, const MapCheckLimits& limits) {
  const long disagreeing_pairs = std::lround(check.disagreeing_fraction * check.two_view_pairs);
  return check.two_view_pairs > 0 &&
         ((check.disagreeing_fraction > limits.max_disagreeing_fraction &&
           disagreeing_pairs >= limits.min_disagreeing_pairs) ||
          check.off_neighbours > 0);
}

std::optional<int> KeyframeToStartFrom(const map::Map& map, const MapCheck& check,
                                       const std::vector<std::uint32_t>& excluded) {
  const int n = static_cast<int>(map.keyframes.size());
  if (static_cast<int>(check.keyframe_agreeing_pairs.size()) != n) return std::nullopt;
  std::vector<int> off;  // keyframe indices
  for (int k = 0; k < n; ++k)
    if (std::find(check.disagreeing_frames.begin(), check.disagreeing_frames.end(), map.keyframes[k].frame_index) !=
        check.disagreeing_frames.end())
      off.push_back(k);
  const auto distance_to_off = [&](int k) {
    int d = n;
    for (int o : off) d = std::min(d, std::abs(o - k));
    return d;
  };
  std::optional<int> best;
  for (int k = 0; k < n; ++k) {
    if (check.keyframe_agreeing_pairs[k] == 0 || distance_to_off(k) == 0 ||
        std::find(excluded.begin(), excluded.end(), map.keyframes[k].colmap_image_id) != excluded.end())
      continue;
    if (!best || check.keyframe_agreeing_pairs[k] > check.keyframe_agreeing_pairs[*best] ||
        (check.keyframe_agreeing_pairs[k] == check.keyframe_agreeing_pairs[*best] &&
         distance_to_off(k) > distance_to_off(*best)))
      best = k;
  }
  return best;
}

Eigen::Matrix3d EssentialBetween(const calib::Pose& a, const calib::Pose& b) {
  const Eigen::Matrix3d r = b.R() * a.R().transpose();
  const Eigen::Vector3d t = b.t_cw - r * a.t_cw;
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  return tx * r;
}

std::optional<double> RotationDisagreementDeg(const Eigen::Matrix3d& essential, const Eigen::Matrix3d& rotation_ab) {
  if (!essential.allFinite() || essential.norm() < 1e-12) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(essential, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (s(1) < 1e-6 * s(0)) return std::nullopt;  // rank one: no motion recoverable
  Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  if (u.determinant() < 0) u = -u;
  if (v.determinant() < 0) v = -v;
  Eigen::Matrix3d w;
  w << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const auto off_deg = [&](const Eigen::Matrix3d& candidate) {
    return Eigen::AngleAxisd(candidate.transpose() * rotation_ab).angle() * 180.0 / M_PI;
  };
  return std::min(off_deg(u * w * v.transpose()), off_deg(u * w.transpose() * v.transpose()));
}

MapCheck CheckMap(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                  const std::vector<TwoViewGeometry>& two_view, const MapCheckLimits& limits) {
  MapCheck c;
  c.keyframes = static_cast<int>(map.keyframes.size());
  std::vector<Eigen::Vector3d> centres;
  for (const map::Keyframe& k : map.keyframes) centres.push_back(k.pose.Center());

  std::vector<double> explained;
  for (std::size_t k = 0; k < map.keyframes.size() && k < keypoints.size(); ++k)
    if (!keypoints[k].empty())
      explained.push_back(static_cast<double>(map.keyframes[k].observations.size()) /
                          static_cast<double>(keypoints[k].size()));
  c.explained_fraction = Median(explained);

  for (std::size_t i = 0; i < centres.size(); ++i)
    for (std::size_t j = i + 1; j < centres.size(); ++j)
      c.path_extent = std::max(c.path_extent, (centres[i] - centres[j]).norm());
  c.scene_depth = SceneDepth(map);
  c.extent_ratio = c.scene_depth > 0 ? c.path_extent / c.scene_depth : 0;
  c.median_triangulation_deg = MedianTriangulationDeg(map, centres);

  std::vector<double> still;
  for (std::size_t k = 0; k + 1 < map.keyframes.size() && k + 1 < keypoints.size(); ++k) {
    const auto motion = PointMotion(map.keyframes[k], map.keyframes[k + 1]);
    if (!motion || *motion < limits.moving_pair_px) continue;
    still.push_back(StillFraction(keypoints[k], keypoints[k + 1], limits.still_radius_px));
  }
  c.moving_pairs = static_cast<int>(still.size());
  c.still_fraction = Median(still);
  CompareTwoViewRotations(map, keypoints, two_view, limits, c);
  AddWarnings(c, limits);
  return c;
}

std::string DescribeMapCheck(const MapCheck& c) {
  return "explains " + Percent(c.explained_fraction) + " of the frames' features (median per keyframe); camera path " +
         Fixed(c.extent_ratio, 2) + " x the scene depth; triangulation angle median " +
         Fixed(c.median_triangulation_deg, 1) + " deg; features staying still " + Percent(c.still_fraction) +
         " (median of " + std::to_string(c.moving_pairs) + " keyframe pairs)" +
         (c.two_view_pairs > 0 ? "; rotations disagree with the two-view geometry in " + Percent(c.disagreeing_fraction) +
                                     " of " + std::to_string(c.two_view_pairs) + " pairs (median pair " +
                                     Fixed(c.median_disagreement_deg, 2) + " deg; " + std::to_string(c.fitted_pairs) +
                                     " fitted by the map's poses; keyframes off: " +
                                     std::to_string(c.disagreeing_frames.size()) + ")"
                               : std::string());
}

void WriteMapCheck(const MapCheck& c, const fs::path& file) {
  const json j = {{"keyframes", c.keyframes},
                  {"explained_fraction", c.explained_fraction},
                  {"path_extent", c.path_extent},
                  {"scene_depth", c.scene_depth},
                  {"extent_ratio", c.extent_ratio},
                  {"median_triangulation_deg", c.median_triangulation_deg},
                  {"moving_pairs", c.moving_pairs},
                  {"still_fraction", c.still_fraction},
                  {"two_view_pairs", c.two_view_pairs},
                  {"disagreeing_fraction", c.disagreeing_fraction},
                  {"median_disagreement_deg", c.median_disagreement_deg},
                  {"keyframe_off_deg", c.keyframe_off_deg},
                  {"fitted_pairs", c.fitted_pairs},
                  {"off_neighbours", c.off_neighbours},
                  {"disagreeing_frames", c.disagreeing_frames},
                  {"flagged", c.flagged()},
                  {"warnings", c.warnings}};
  WriteFileAtomically(file, j.dump(2) + "\n");
}

namespace {

std::optional<MapCheck> ReadMapCheckFile(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    // Absent: a map from before the check. A name too long, a folder that cannot be searched: said.
    if (ec) throw map::MapError(file.string() + ": cannot be looked up (" + ec.message() + ")");
    return std::nullopt;
  }
  try {
    const json j = json::parse(ReadFileUpTo(file, 1 << 20));
    MapCheck c;
    c.keyframes = j.at("keyframes").get<int>();
    c.explained_fraction = j.at("explained_fraction").get<double>();
    c.path_extent = j.at("path_extent").get<double>();
    c.scene_depth = j.at("scene_depth").get<double>();
    c.extent_ratio = j.at("extent_ratio").get<double>();
    c.median_triangulation_deg = j.at("median_triangulation_deg").get<double>();
    c.moving_pairs = j.at("moving_pairs").get<int>();
    c.still_fraction = j.at("still_fraction").get<double>();
    // Absent from check files written before the two-view comparison (2026-12-03).
    c.two_view_pairs = j.value("two_view_pairs", 0);
    c.disagreeing_fraction = j.value("disagreeing_fraction", 0.0);
    // Absent from check files written before keyframes were judged by their own pairs (2026-12-04).
    c.median_disagreement_deg = j.value("median_disagreement_deg", 0.0);
    c.keyframe_off_deg = j.value("keyframe_off_deg", 0.0);
    c.off_neighbours = j.value("off_neighbours", 0);
    // Absent from check files written before pairs were fitted with the map's poses (2026-12-06).
    c.fitted_pairs = j.value("fitted_pairs", 0);
    c.disagreeing_frames = j.value("disagreeing_frames", std::vector<int>{});
    c.warnings = j.at("warnings").get<std::vector<std::string>>();
    return c;
  } catch (const json::exception& e) {
    throw map::MapError(file.string() + ": not a map check file (" + e.what() + ")");
  } catch (const InputError& e) {
    throw map::MapError(e.what());
  }
}

}  // namespace

std::optional<MapCheck> ReadMapCheck(const fs::path& file) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<map::MapError>(file.string(), [&] { return ReadMapCheckFile(file); });
}

}  // namespace arview::mapping
