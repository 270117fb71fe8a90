#include "recordings/accuracy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/point_spread.h"

namespace arview::recordings {

calib::Pose Transform(const Sim3& transform, const calib::Pose& pose) {
  return calib::Pose::FromRigid(transform.TransformPose(pose.ToRigid()));
}

AlignMode ParseAlignMode(const std::string& text) { return ParseEnum<AlignMode, RecordingError>(text, "alignment"); }

Sim3 Umeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool with_scale) {
  try {
    return EstimateSim3(src, dst, with_scale, "alignment");
  } catch (const RecordingError&) {
    throw;
  } catch (const Error& e) {
    throw RecordingError(e.what());
  }
}

std::vector<std::pair<size_t, size_t>> AssociateByTimestamp(const Trajectory& a, const Trajectory& b, double max_dt) {
  if (!(max_dt >= 0) || !std::isfinite(max_dt)) {
    throw RecordingError("association tolerance must be a non-negative number of seconds");
  }
  std::vector<size_t> b_sorted(b.size());
  std::iota(b_sorted.begin(), b_sorted.end(), size_t{0});
  std::sort(b_sorted.begin(), b_sorted.end(), [&](size_t x, size_t y) { return b[x].timestamp < b[y].timestamp; });
  struct Candidate {
    double dt;
    size_t i, j;
  };
  std::vector<Candidate> candidates;
  // Per pose of a, the nearest few of b on each side within the tolerance: enough for the
  // one-to-one matching, and bounded even when the tolerance spans whole trajectories.
  constexpr std::ptrdiff_t kPerSide = 4;
  for (size_t i = 0; i < a.size(); ++i) {
    const double t = a[i].timestamp;
    const auto mid = std::lower_bound(b_sorted.begin(), b_sorted.end(), t,
                                      [&](size_t j, double value) { return b[j].timestamp < value; });
    const auto first = mid - std::min(kPerSide, mid - b_sorted.begin());
    const auto last = mid + std::min(kPerSide, b_sorted.end() - mid);
    for (auto it = first; it != last; ++it) {
      const double dt = std::abs(b[*it].timestamp - t);
      if (dt <= max_dt) candidates.push_back({dt, i, *it});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.dt < y.dt;
  });
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = true;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end(), [&](const auto& x, const auto& y) {
    return a[x.first].timestamp < a[y.first].timestamp;
  });
  return pairs;
}

Sim3 FitAlignment(const Trajectory& from, const Trajectory& to, AlignMode mode, double max_dt) {
  if (mode == AlignMode::kNone) return {};
  const auto pairs = AssociateByTimestamp(from, to, max_dt);
  if (pairs.size() < 3) {
    throw RecordingError("alignment: only " + std::to_string(pairs.size()) +
                         " poses share a timestamp with the ground truth (tolerance " + std::to_string(max_dt) +
                         " s); at least 3 are needed");
  }
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [i, j] : pairs) {
    src.push_back(from[i].pose.Center());
    dst.push_back(to[j].pose.Center());
  }
  return Umeyama(src, dst, mode == AlignMode::kSim3);
}

Trajectory TransformTrajectory(const Trajectory& trajectory, const Sim3& transform) {
  Trajectory out;
  out.reserve(trajectory.size());
  for (const StampedPose& p : trajectory) out.push_back({p.timestamp, Transform(transform, p.pose)});
  return out;
}

void RequirePositionsInRange(const Trajectory& trajectory, const std::string& what) {
  for (const StampedPose& p : trajectory) {
    const Eigen::Vector3d c = p.pose.Center();
    if (!c.allFinite() || c.norm() > kMaxPositionNorm) {
      std::ostringstream message;
      message << what << ": the pose at " << p.timestamp << " s is at (" << c.x() << ", " << c.y() << ", " << c.z()
              << "), beyond " << kMaxPositionNorm << " of the origin";
      throw RecordingError(message.str());
    }
  }
}

double RotationErrorDeg(const calib::Pose& a, const calib::Pose& b) {
  return a.q_cw.angularDistance(b.q_cw) * 180.0 / M_PI;
}

namespace {

// Relative motion from pose i to pose j, camera-to-world frames: (R_i^T R_j, R_i^T (C_j - C_i)).
struct Motion {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
};

Motion Relative(const calib::Pose& i, const calib::Pose& j) {
  const Eigen::Quaterniond qi = i.CameraToWorldRotation(), qj = j.CameraToWorldRotation();
  return {qi.conjugate() * qj, qi.conjugate() * (j.Center() - i.Center())};
}

}  // namespace

AccuracyReport EvaluateTrajectory(const Trajectory& estimate, const Trajectory& groundtruth,
                                  const AccuracyOptions& options) {
  if (estimate.empty()) throw RecordingError("evaluation: the estimated trajectory is empty");
  if (groundtruth.empty()) throw RecordingError("evaluation: the ground-truth trajectory is empty");
  if (options.rpe_delta < 1) throw RecordingError("evaluation: the RPE interval must be at least 1 frame");
  AccuracyReport r;
  r.align = options.align;
  r.aligned_with_other = options.align_with != nullptr;
  r.estimate_poses = static_cast<int>(estimate.size());
  r.groundtruth_poses = static_cast<int>(groundtruth.size());
  r.rpe_delta = options.rpe_delta;
  RequirePositionsInRange(estimate, "evaluation: the estimate");
  RequirePositionsInRange(groundtruth, "evaluation: the ground truth");
  if (options.align_with) RequirePositionsInRange(*options.align_with, "evaluation: the trajectory the alignment is fitted on");
  const Trajectory& fit_on = options.align_with ? *options.align_with : estimate;
  r.alignment = FitAlignment(fit_on, groundtruth, options.align, options.max_dt);
  if (options.align != AlignMode::kNone) {
    r.alignment_pairs = static_cast<int>(AssociateByTimestamp(fit_on, groundtruth, options.max_dt).size());
  }
  r.aligned_estimate = TransformTrajectory(estimate, r.alignment);
  // A scale fitted on other poses (--align-with, or the associated ones) can carry the others far.
  RequirePositionsInRange(r.aligned_estimate, "evaluation: the estimate aligned with a scale of " +
                                                  std::to_string(r.alignment.scale));
  r.pairs = AssociateByTimestamp(estimate, groundtruth, options.max_dt);
  if (r.pairs.empty()) {
    throw RecordingError("evaluation: no estimated pose has a ground-truth pose within " +
                         std::to_string(options.max_dt) + " s of its timestamp");
  }
  r.associated = static_cast<int>(r.pairs.size());
  r.coverage = static_cast<double>(r.associated) / static_cast<double>(r.groundtruth_poses);
  for (const auto& [i, j] : r.pairs) {
    const calib::Pose& e = r.aligned_estimate[i].pose;
    const calib::Pose& g = groundtruth[j].pose;
    r.position_errors.push_back((e.Center() - g.Center()).norm());
    r.rotation_errors_deg.push_back(RotationErrorDeg(e, g));
  }
  r.ate = Summarize(r.position_errors);
  r.rotation_deg = Summarize(r.rotation_errors_deg);
  std::vector<double> rpe_t, rpe_r;
  const size_t delta = static_cast<size_t>(options.rpe_delta);
  for (size_t k = 0; k + delta < r.pairs.size(); ++k) {
    const auto [ei, gi] = r.pairs[k];
    const auto [ej, gj] = r.pairs[k + delta];
    const Motion m_gt = Relative(groundtruth[gi].pose, groundtruth[gj].pose);
    const Motion m_est = Relative(r.aligned_estimate[ei].pose, r.aligned_estimate[ej].pose);
    // Error motion m_gt^-1 · m_est.
    rpe_t.push_back((m_gt.q.conjugate() * (m_est.t - m_gt.t)).norm());
    rpe_r.push_back(m_gt.q.angularDistance(m_est.q) * 180.0 / M_PI);
  }
  r.rpe_translation = Summarize(rpe_t);
  r.rpe_rotation_deg = Summarize(rpe_r);
  return r;
}

namespace {

nlohmann::ordered_json StatsJson(const ErrorStats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"max", s.max}, {"count", s.count}};
}

std::string RpeNotComputed(const AccuracyReport& r) {
  return "fewer than " + std::to_string(r.rpe_delta + 1) + " associated poses";
}

}  // namespace

std::string ReportToJson(const AccuracyReport& r) {
  // Keys in the order people read them (ordered_json keeps insertion order).
  nlohmann::ordered_json j;
  j["align"] = ToString(r.align);
  j["aligned_with_other_trajectory"] = r.aligned_with_other;
  j["alignment_pairs"] = r.alignment_pairs;
  std::vector<double> rotation;
  for (int i = 0; i < 9; ++i) rotation.push_back(r.alignment.R(i / 3, i % 3));
  j["alignment"] = {{"scale", r.alignment.scale},
                    {"R", rotation},
                    {"t", {r.alignment.t.x(), r.alignment.t.y(), r.alignment.t.z()}}};
  j["estimate_poses"] = r.estimate_poses;
  j["groundtruth_poses"] = r.groundtruth_poses;
  j["associated"] = r.associated;
  j["coverage"] = r.coverage;
  j["ate"] = StatsJson(r.ate);
  j["rotation_deg"] = StatsJson(r.rotation_deg);
  j["rpe_delta"] = r.rpe_delta;
  // No pairs: null and the reason, as the text says "not computed" (summaries of nothing read 0).
  if (r.rpe_translation.count > 0) {
    j["rpe_translation"] = StatsJson(r.rpe_translation);
    j["rpe_rotation_deg"] = StatsJson(r.rpe_rotation_deg);
  } else {
    j["rpe_translation"] = nullptr;
    j["rpe_rotation_deg"] = nullptr;
    j["rpe_not_computed"] = RpeNotComputed(r);
  }
  return j.dump(2) + "\n";
}

std::string ReportToText(const AccuracyReport& r) {
  char buf[512];
  std::ostringstream o;
  if (r.align == AlignMode::kNone) {
    o << "alignment   none\n";
  } else {
    std::snprintf(buf, sizeof(buf), "alignment   %s, scale %.6g, fitted on %d pose pairs of %s\n",
                  ToString(r.align).c_str(), r.alignment.scale, r.alignment_pairs,
                  r.aligned_with_other ? "the --align-with trajectory" : "the estimate");
    o << buf;
  }
  std::snprintf(buf, sizeof(buf), "coverage    %d of %d ground-truth poses have an estimate (%.1f%%); %d estimated poses\n",
                r.associated, r.groundtruth_poses, 100.0 * r.coverage, r.estimate_poses);
  o << buf;
  std::snprintf(buf, sizeof(buf), "ATE         rmse %.6g  mean %.6g  median %.6g  max %.6g\n", r.ate.rmse, r.ate.mean,
                r.ate.median, r.ate.max);
  o << buf;
  std::snprintf(buf, sizeof(buf), "rotation    median %.4g deg  max %.4g deg\n", r.rotation_deg.median,
                r.rotation_deg.max);
  o << buf;
  if (r.rpe_translation.count > 0) {
    std::snprintf(buf, sizeof(buf), "RPE (%d)     translation rmse %.6g  median %.6g; rotation rmse %.4g deg  median %.4g deg\n",
                  r.rpe_delta, r.rpe_translation.rmse, r.rpe_translation.median, r.rpe_rotation_deg.rmse,
                  r.rpe_rotation_deg.median);
  } else {
    std::snprintf(buf, sizeof(buf), "RPE (%d)     not computed: %s\n", r.rpe_delta, RpeNotComputed(r).c_str());
  }
  o << buf;
  return o.str();
}

}  // namespace arview::recordings
