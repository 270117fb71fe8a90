#include "recordings/registration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "recordings/recording.h"

namespace arview::recordings {

namespace {

constexpr double kArcminPerRadian = 180.0 / M_PI * 60.0;
// Two ground-truth poses this close are one tripod position: a rendered recording's still
// frames repeat one pose exactly, up to the TUM file's printed digits.
constexpr double kStillCentre = 1e-6;
constexpr double kStillAngleRad = 1e-5;
constexpr double kSameFrameS = 1e-4;

bool SamePlace(const calib::Pose& a, const calib::Pose& b) {
  return (a.Center() - b.Center()).norm() < kStillCentre && a.q_cw.angularDistance(b.q_cw) < kStillAngleRad;
}

// Runs [first, last] of ground-truth indices whose poses do not move, at least min_s long.
std::vector<std::pair<size_t, size_t>> StillRuns(const Trajectory& groundtruth, double min_s) {
  std::vector<std::pair<size_t, size_t>> runs;
  size_t first = 0;
  for (size_t j = 1; j <= groundtruth.size(); ++j) {
    if (j < groundtruth.size() && SamePlace(groundtruth[j].pose, groundtruth[first].pose)) continue;
    if (groundtruth[j - 1].timestamp - groundtruth[first].timestamp >= min_s) runs.emplace_back(first, j - 1);
    first = j;
  }
  return runs;
}

double RmsOfNorms(const std::vector<Eigen::Vector2d>& residuals) {
  double sum = 0;
  for (const Eigen::Vector2d& r : residuals) sum += r.squaredNorm();
  return residuals.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(residuals.size()));
}

// The pose with orientation `oriented`'s and its centre moved to `centre`.
calib::Pose WithCentre(const calib::Pose& oriented, const Eigen::Vector3d& centre) {
  return {oriented.q_cw, -(oriented.q_cw * centre)};
}

std::optional<Eigen::Vector2d> ProjectInFront(const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& x) {
  const Eigen::Vector3d c = pose.ToCamera(x);
  if (!(c.z() > 0)) return std::nullopt;
  return camera.Project(c);
}

// Linear interpolation of the centres at time t, between neighbours at most max_gap apart.
std::optional<Eigen::Vector3d> CentreAt(const std::vector<StampedCentre>& c, double t, double max_gap) {
  const auto after = std::lower_bound(c.begin(), c.end(), t, [](const StampedCentre& s, double v) { return s.timestamp < v; });
  if (after == c.end()) return std::nullopt;
  if (after->timestamp == t) return after->centre;
  if (after == c.begin()) return std::nullopt;
  const auto before = after - 1;
  const double gap = after->timestamp - before->timestamp;
  if (gap > max_gap) return std::nullopt;
  const double w = (t - before->timestamp) / gap;
  return ((1 - w) * before->centre + w * after->centre).eval();
}

// The centre stamped within `tolerance` of t: the same frame, its time printed with fewer digits
// in a trajectory file than in stats.json.
std::optional<Eigen::Vector3d> NearestCentre(const std::vector<StampedCentre>& c, double t, double tolerance) {
  const auto after = std::lower_bound(c.begin(), c.end(), t, [](const StampedCentre& s, double v) { return s.timestamp < v; });
  std::optional<Eigen::Vector3d> best;
  double best_dt = tolerance;
  for (auto it : {after, after == c.begin() ? c.end() : after - 1}) {
    if (it == c.end() || std::abs(it->timestamp - t) > best_dt) continue;
    best_dt = std::abs(it->timestamp - t);
    best = it->centre;
  }
  return best;
}

double MedianInterval(const std::vector<StampedCentre>& c) {
  std::vector<double> dt;
  for (size_t i = 1; i < c.size(); ++i) dt.push_back(c[i].timestamp - c[i - 1].timestamp);
  return Median(dt);
}

struct Scored {
  std::vector<double> mean_px, max_px;
};

// Per associated frame, over the points in front of both cameras (and, with only_in_image, in
// the true camera's image).
Scored ScoreFrames(const AccuracyReport& a, const Trajectory& groundtruth, const calib::Camera& camera,
                   const std::vector<Eigen::Vector3d>& points_gt, bool only_in_image) {
  Scored s;
  for (const auto& [i, j] : a.pairs) {
    double sum = 0, worst = 0;
    int seen = 0;
    for (const Eigen::Vector3d& x : points_gt) {
      const auto estimated = ProjectInFront(camera, a.aligned_estimate[i].pose, x);
      const auto truth = ProjectInFront(camera, groundtruth[j].pose, x);
      if (!estimated || !truth || (only_in_image && !camera.InImage(*truth))) continue;
      const double e = (*estimated - *truth).norm();
      sum += e;
      worst = std::max(worst, e);
      ++seen;
    }
    if (seen == 0) continue;
    s.mean_px.push_back(sum / seen);
    s.max_px.push_back(worst);
  }
  return s;
}

StillSegment JudgeStill(const AccuracyReport& a, const Trajectory& groundtruth, const calib::Camera& camera,
                        const Eigen::Vector3d& anchor_gt, std::pair<size_t, size_t> run, const RegistrationOptions& o) {
  StillSegment still;
  still.start_s = groundtruth[run.first].timestamp;
  still.end_s = groundtruth[run.second].timestamp;
  still.anchor_distance = (groundtruth[run.first].pose.Center() - anchor_gt).norm();
  std::vector<double> times, smoothed_times;
  std::vector<Eigen::Vector2d> raw, smoothed;
  for (const auto& [i, j] : a.pairs) {
    if (j < run.first || j > run.second) continue;
    const calib::Pose& pose = a.aligned_estimate[i].pose;
    const auto u = ProjectInFront(camera, pose, anchor_gt);
    if (!u) continue;
    times.push_back(a.aligned_estimate[i].timestamp);
    raw.push_back(*u);
    if (o.smoothed == nullptr) continue;
    const double t = a.aligned_estimate[i].timestamp;
    const auto c = NearestCentre(*o.smoothed, t, kSameFrameS);
    if (!c) continue;
    const Eigen::Vector3d centre_gt = a.alignment(*c);
    const auto us = ProjectInFront(camera, WithCentre(pose, centre_gt), anchor_gt);
    if (!us) continue;
    smoothed_times.push_back(t);
    smoothed.push_back(*us);
  }
  still.frames = static_cast<int>(raw.size());
  const double f = 0.5 * (camera.fx + camera.fy);
  still.jitter_px = RmsOfNorms(RemoveTrend(times, raw, o.trend_window_s));
  still.jitter_arcmin = still.jitter_px / f * kArcminPerRadian;
  still.jitter_mm = still.jitter_px / f * still.anchor_distance * 1000.0;
  if (o.smoothed != nullptr && !smoothed.empty()) {
    still.smoothed_jitter_px = RmsOfNorms(RemoveTrend(smoothed_times, smoothed, o.trend_window_s));
  }
  return still;
}

// The anchor's error vector (estimate − truth) over the frames outside the still runs, less its
// trend: the part of the error faster than the window.
std::optional<double> FastError(const AccuracyReport& a, const Trajectory& groundtruth, const calib::Camera& camera,
                                const Eigen::Vector3d& anchor_gt, const std::vector<std::pair<size_t, size_t>>& stills,
                                double window_s) {
  std::vector<double> times;
  std::vector<Eigen::Vector2d> errors;
  for (const auto& [i, j] : a.pairs) {
    const bool still = std::any_of(stills.begin(), stills.end(), [j = j](auto r) { return j >= r.first && j <= r.second; });
    if (still) continue;
    const auto estimated = ProjectInFront(camera, a.aligned_estimate[i].pose, anchor_gt);
    const auto truth = ProjectInFront(camera, groundtruth[j].pose, anchor_gt);
    if (!estimated || !truth) continue;
    times.push_back(a.aligned_estimate[i].timestamp);
    errors.push_back(*estimated - *truth);
  }
  const std::vector<Eigen::Vector2d> fast = RemoveTrend(times, errors, window_s);
  if (fast.empty()) return std::nullopt;
  return RmsOfNorms(fast);
}

// Ground-truth poses between the estimate's first and last timestamp: the frames it was asked
// to place (a lost frame has no estimate but lies in the span).
int GroundTruthInSpan(const Trajectory& estimate, const Trajectory& groundtruth) {
  double first = std::numeric_limits<double>::infinity(), last = -first;
  for (const StampedPose& p : estimate) first = std::min(first, p.timestamp), last = std::max(last, p.timestamp);
  return static_cast<int>(std::count_if(groundtruth.begin(), groundtruth.end(), [&](const StampedPose& g) {
    return g.timestamp >= first && g.timestamp <= last;
  }));
}

nlohmann::ordered_json PixelStatsJson(const ErrorStats& s) {
  return {{"median", s.median}, {"p95", s.p95}, {"max", s.max}, {"mean", s.mean}, {"count", s.count}};
}

}  // namespace

std::vector<Eigen::Vector2d> RemoveTrend(const std::vector<double>& times, const std::vector<Eigen::Vector2d>& values,
                                         double window_s) {
  std::vector<Eigen::Vector2d> out;
  if (times.empty()) return out;
  // Half the window, and a microsecond more: frames at ±half exactly are in, whatever the
  // rounding of their timestamps, so that an evenly sampled window is symmetric.
  const double half = 0.5 * window_s + 1e-6;
  size_t lo = 0, hi = 0;  // the window [lo, hi) round sample k
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < times.size(); ++k) {
    while (hi < times.size() && times[hi] <= times[k] + half) sum += values[hi++];
    while (times[lo] < times[k] - half) sum -= values[lo++];
    if (times[k] - half + 2e-6 < times.front() || times[k] + half - 2e-6 > times.back()) continue;
    out.push_back(values[k] - sum / static_cast<double>(hi - lo));
  }
  return out;
}

std::optional<double> LagSeconds(const std::vector<StampedCentre>& raw, const std::vector<StampedCentre>& smoothed,
                                 double max_shift_s, int* samples) {
  if (raw.size() < 10 || smoothed.size() < 10) return std::nullopt;
  const double max_gap = 2.0 * MedianInterval(raw);
  constexpr double kStep = 1e-3;  // seconds: 0.03 frames at 30 fps
  double best_cost = std::numeric_limits<double>::infinity(), best_shift = 0;
  int best_count = 0;
  const int steps = static_cast<int>(std::round(max_shift_s / kStep));
  for (int k = -steps; k <= steps; ++k) {
    const double shift = k * kStep;
    double cost = 0;
    int count = 0;
    for (const StampedCentre& s : smoothed) {
      const auto r = CentreAt(raw, s.timestamp - shift, max_gap);
      if (!r) continue;
      cost += (s.centre - *r).squaredNorm();
      ++count;
    }
    if (count < 10) continue;
    cost /= count;
    if (cost < best_cost) best_cost = cost, best_shift = shift, best_count = count;
  }
  if (samples != nullptr) *samples = best_count;
  if (best_count < 10) return std::nullopt;
  return best_shift;
}

std::vector<RecallAt> Recall(const AccuracyReport& a, const Trajectory& groundtruth,
                             const std::vector<std::pair<double, double>>& thresholds) {
  // A pose associated just outside the span (the association's tolerance) is judged too.
  const int judged = std::max(GroundTruthInSpan(a.aligned_estimate, groundtruth), a.associated);
  std::vector<RecallAt> out;
  for (const auto& [metres, degrees] : thresholds) {
    int hits = 0;
    for (size_t k = 0; k < a.position_errors.size(); ++k) {
      hits += a.position_errors[k] <= metres && a.rotation_errors_deg[k] <= degrees;
    }
    out.push_back({metres, degrees, judged > 0 ? static_cast<double>(hits) / judged : 0.0});
  }
  return out;
}

RegistrationReport EvaluateRegistration(const AccuracyReport& a, const Trajectory& estimate, const Trajectory& groundtruth,
                                        const calib::Camera& camera, const RegistrationOptions& o) {
  RegistrationReport r;
  r.over_px = o.over_px;
  r.recall = Recall(a, groundtruth, {{0.01, 1.0}, {0.02, 2.0}, {0.05, 5.0}});
  r.judged_groundtruth = std::max(GroundTruthInSpan(estimate, groundtruth), a.associated);
  if (o.smoothed != nullptr) {
    std::vector<StampedCentre> raw;
    for (const StampedPose& p : estimate) raw.push_back({p.timestamp, p.pose.Center()});
    std::sort(raw.begin(), raw.end(), [](const auto& x, const auto& y) { return x.timestamp < y.timestamp; });
    const auto lag = LagSeconds(raw, *o.smoothed, o.max_lag_s, &r.lag_samples);
    if (lag) r.lag_frames = *lag / MedianInterval(raw);
  }
  r.points = static_cast<int>(o.points.size());
  if (!o.groundtruth_points.empty()) {
    const Scored geometry = ScoreFrames(a, groundtruth, camera, o.groundtruth_points, true);
    r.geometry_frames = static_cast<int>(geometry.mean_px.size());
    r.geometry_mean_px = Summarize(geometry.mean_px);
  }
  if (o.points.empty()) return r;
  std::vector<Eigen::Vector3d> points_gt;
  for (const Eigen::Vector3d& x : o.points) points_gt.push_back(a.alignment(x));
  const Scored scored = ScoreFrames(a, groundtruth, camera, points_gt, false);
  if (scored.mean_px.empty()) {
    throw RecordingError("registration: no associated frame has any of the " + std::to_string(o.points.size()) +
                         " points in front of both its estimated and its true camera");
  }
  r.frames = static_cast<int>(scored.mean_px.size());
  r.frame_mean_px = Summarize(scored.mean_px);
  r.frame_max_px = Summarize(scored.max_px);
  r.share_over = static_cast<double>(std::count_if(scored.max_px.begin(), scored.max_px.end(),
                                                   [&](double e) { return e > o.over_px; })) /
                 static_cast<double>(r.frames);
  r.per_frame_mean_px = scored.mean_px;
  const std::vector<std::pair<size_t, size_t>> runs = StillRuns(groundtruth, o.min_still_s);
  for (const auto& run : runs) {
    StillSegment still = JudgeStill(a, groundtruth, camera, points_gt.front(), run, o);
    if (still.frames > 0) r.stills.push_back(still);
  }
  r.fast_error_px = FastError(a, groundtruth, camera, points_gt.front(), runs, o.trend_window_s);
  return r;
}

std::string RegistrationToJson(const RegistrationReport& r) {
  nlohmann::ordered_json j;
  j["points"] = r.points;
  j["frames"] = r.frames;
  if (r.frames > 0) {
    j["frame_mean_px"] = PixelStatsJson(r.frame_mean_px);
    j["frame_max_px"] = PixelStatsJson(r.frame_max_px);
    j["over_px"] = r.over_px;
    j["share_over"] = r.share_over;
  }
  if (r.fast_error_px) j["fast_error_px"] = *r.fast_error_px;
  if (r.geometry_frames > 0) {
    j["geometry_frames"] = r.geometry_frames;
    j["geometry_mean_px"] = PixelStatsJson(r.geometry_mean_px);
  }
  nlohmann::ordered_json stills = nlohmann::ordered_json::array();
  for (const StillSegment& s : r.stills) {
    nlohmann::ordered_json one = {{"start_s", s.start_s},         {"end_s", s.end_s},
                                  {"frames", s.frames},           {"anchor_distance", s.anchor_distance},
                                  {"jitter_px", s.jitter_px},     {"jitter_arcmin", s.jitter_arcmin},
                                  {"jitter_mm", s.jitter_mm}};
    if (s.smoothed_jitter_px) one["smoothed_jitter_px"] = *s.smoothed_jitter_px;
    stills.push_back(one);
  }
  j["stills"] = stills;
  if (r.lag_frames) j["lag_frames"] = *r.lag_frames;
  j["judged_groundtruth"] = r.judged_groundtruth;
  nlohmann::ordered_json recall = nlohmann::ordered_json::array();
  for (const RecallAt& k : r.recall) recall.push_back({{"metres", k.metres}, {"degrees", k.degrees}, {"recall", k.recall}});
  j["recall"] = recall;
  return j.dump(2);
}

std::string RegistrationToText(const RegistrationReport& r) {
  char buf[512];
  std::ostringstream o;
  std::string recall;
  for (const RecallAt& k : r.recall) {
    std::snprintf(buf, sizeof buf, "%s%.0f cm/%.0f deg %.1f%%", recall.empty() ? "" : ", ", 100 * k.metres, k.degrees,
                  100 * k.recall);
    recall += buf;
  }
  o << "recall      " << recall << " (of " << r.judged_groundtruth << " ground-truth poses in the estimate's span)\n";
  if (r.frames > 0) {
    std::snprintf(buf, sizeof buf,
                  "registration %d points, %d frames: mean per frame median %.3g px  p95 %.3g px  max %.3g px; worst point "
                  "median %.3g px  p95 %.3g px  max %.3g px; %.1f%% of frames over %.3g px\n",
                  r.points, r.frames, r.frame_mean_px.median, r.frame_mean_px.p95, r.frame_mean_px.max,
                  r.frame_max_px.median, r.frame_max_px.p95, r.frame_max_px.max, 100 * r.share_over, r.over_px);
    o << buf;
  }
  if (r.fast_error_px) {
    std::snprintf(buf, sizeof buf, "fast error  %.3g px RMS: the anchor's error less its 1 s trend, moving frames\n",
                  *r.fast_error_px);
    o << buf;
  }
  if (r.geometry_frames > 0) {
    std::snprintf(buf, sizeof buf,
                  "geometry    %d frames, the true scene's points each frame sees: mean per frame median %.3g px  p95 "
                  "%.3g px  max %.3g px\n",
                  r.geometry_frames, r.geometry_mean_px.median, r.geometry_mean_px.p95, r.geometry_mean_px.max);
    o << buf;
  }
  for (const StillSegment& s : r.stills) {
    std::snprintf(buf, sizeof buf,
                  "still       %.2f-%.2f s, %d frames: jitter %.3g px RMS (%.3g arcmin, %.3g mm at the anchor's %.2f)",
                  s.start_s, s.end_s, s.frames, s.jitter_px, s.jitter_arcmin, s.jitter_mm, s.anchor_distance);
    o << buf;
    if (s.smoothed_jitter_px) {
      std::snprintf(buf, sizeof buf, "; with the smoothed centre %.3g px", *s.smoothed_jitter_px);
      o << buf;
    }
    o << "\n";
  }
  if (r.lag_frames) {
    std::snprintf(buf, sizeof buf, "smoothing   lags the raw centre by %.2f frames (%d frames compared)\n", *r.lag_frames,
                  r.lag_samples);
    o << buf;
  }
  return o.str();
}

}  // namespace arview::recordings
