#include "anim/prepared_clip.h"

#include "anim/morph.h"
#include "anim/taylor_trig.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace arview::anim {
namespace {

// Index (from the timeline's start) of the last key with time ≤ t and the fraction toward the
// next key: SamplingJob's Locate on one timeline.
struct Located {
  int index = 0;
  double fraction = 0;
};

Located Locate(const double* times, int count, double t) {
  if (t <= times[0]) return {0, 0.0};
  if (t >= times[count - 1]) return {count - 1, 0.0};
  const int i = static_cast<int>(std::upper_bound(times, times + count, t) - times) - 1;
  const double span = times[i + 1] - times[i];
  return {i, span > 0 ? (t - times[i]) / span : 0.0};
}

// DualQuatd::FromRotationTranslation, inlined here.
DualQuatd Rigid(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) {
  const Eigen::Quaterniond rn = r.normalized();
  const Eigen::Quaterniond tq(0.0, t.x() * 0.5, t.y() * 0.5, t.z() * 0.5);
  return DualQuatd(rn, tq * rn);
}

}  // namespace

PreparedClip::PreparedClip(const Skeleton& skeleton, const Clip& clip, bool nlerp, std::span<const int> joints)
    : duration_(clip.duration),
      joint_count_(skeleton.size()),
      morph_target_count_(skeleton.morph_target_count()),
      weight_tracks_(clip.weight_tracks) {
  if (static_cast<int>(clip.tracks.size()) != skeleton.size())
    throw Error("clip '" + clip.name + "' has " + std::to_string(clip.tracks.size()) + " tracks for " +
                std::to_string(skeleton.size()) + " joints");
  if (!WeightTracksFit(weight_tracks_, morph_target_count_, 0))
    throw Error("clip '" + clip.name + "' has a weight track for a morph target the skeleton lacks (" +
                std::to_string(morph_target_count_) + " targets)");
  if (joints.empty())
    for (int j = 0; j < skeleton.size(); ++j) joints_.push_back(j);
  else
    joints_.assign(joints.begin(), joints.end());
  for (int j : joints_)
    if (j < 0 || j >= skeleton.size()) throw Error("prepared clip '" + clip.name + "': joint " + std::to_string(j) + " out of range");

  std::map<std::vector<double>, int> timeline_ids;
  auto timeline_of = [&](const auto& keys) {
    std::vector<double> times;
    for (const auto& k : keys) times.push_back(k.time);
    const auto [it, added] = timeline_ids.emplace(times, static_cast<int>(timelines_.size()));
    if (added) {
      timelines_.push_back({static_cast<int>(times_.size()), static_cast<int>(times.size())});
      times_.insert(times_.end(), times.begin(), times.end());
    }
    return it->second;
  };
  auto vector_channel = [&](const std::vector<Key<Eigen::Vector3d>>& keys, const Eigen::Vector3d& rest) {
    Channel c;
    c.first = static_cast<int>(vectors_.size());
    if (keys.size() <= 1) {
      vectors_.push_back(keys.empty() ? rest : keys[0].value);
      return c;
    }
    c.timeline = timeline_of(keys);
    for (const auto& k : keys) vectors_.push_back(k.value);
    return c;
  };
  auto rotation_channel = [&](const std::vector<Key<Eigen::Quaterniond>>& keys, const Eigen::Quaterniond& rest) {
    Channel c;
    c.first = static_cast<int>(rotations_.size());
    if (keys.size() <= 1) {
      rotations_.push_back(keys.empty() ? rest : keys[0].value);
      pairs_.emplace_back();
      return c;
    }
    c.timeline = timeline_of(keys);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      rotations_.push_back(keys[i].value);
      RotationPair p;
      if (i + 1 < keys.size()) {
        // As Eigen's slerp (QuaternionBase::slerp): linear weights when |a·b| ≥ 1 − ε.
        const double d = keys[i].value.coeffs().dot(keys[i + 1].value.coeffs());
        const double abs_d = std::abs(d);
        p.sign = d < 0 ? -1.0 : 1.0;
        if (!nlerp && abs_d < 1 - std::numeric_limits<double>::epsilon()) {
          p.theta = std::acos(abs_d);
          p.inv_sin = 1 / std::sin(p.theta);
        }
      }
      pairs_.push_back(p);
    }
    return c;
  };

  for (int j : joints_) {
    const JointTrack& tr = clip.tracks[j];
    const Transform& rest = skeleton.rest[j];
    JointPlan p;
    p.joint = j;
    p.rotation = rotation_channel(tr.rotation, rest.rotation);
    p.translation = vector_channel(tr.translation, rest.translation);
    p.scale = vector_channel(tr.scale, rest.scale);
    if (p.rotation.timeline < 0 && p.translation.timeline < 0) {
      p.rigid = static_cast<int>(rigids_.size());
      rigids_.push_back(Rigid(rotations_[p.rotation.first], vectors_[p.translation.first]));
    }
    plan_.push_back(p);
  }
}

bool PreparedSamplingJob::Validate() const {
  return clip && output && std::isfinite(time) && output->size() == clip->joint_count() &&
         WeightTracksFit(clip->weight_tracks_, clip->morph_target_count_, output->morph.size());
}

bool PreparedSamplingJob::Run() const {
  if (!Validate()) return false;
  const PreparedClip& c = *clip;
  double t = time;  // as SamplingJob::Run
  if (c.duration_ <= 0) t = 0;
  else if (loop) {
    t = std::fmod(t, c.duration_);
    if (t < 0) t += c.duration_;
  } else t = std::clamp(t, 0.0, c.duration_);

  // Each timeline searched once (the first kCached; any beyond, per channel).
  constexpr int kCached = 16;
  std::array<Located, kCached> located;
  const int timelines = static_cast<int>(c.timelines_.size());
  for (int i = 0; i < std::min(timelines, kCached); ++i)
    located[i] = Locate(c.times_.data() + c.timelines_[i].first, c.timelines_[i].count, t);
  auto at = [&](int id) {
    return id < kCached ? located[id] : Locate(c.times_.data() + c.timelines_[id].first, c.timelines_[id].count, t);
  };
  auto vector = [&](const PreparedClip::Channel& ch) -> Eigen::Vector3d {
    if (ch.timeline < 0) return c.vectors_[ch.first];
    const Located l = at(ch.timeline);
    const Eigen::Vector3d& a = c.vectors_[ch.first + l.index];
    if (l.fraction == 0.0) return a;
    return (1 - l.fraction) * a + l.fraction * c.vectors_[ch.first + l.index + 1];
  };
  auto rotation = [&](const PreparedClip::Channel& ch) -> Eigen::Quaterniond {
    if (ch.timeline < 0) return c.rotations_[ch.first];
    const Located l = at(ch.timeline);
    const int i = ch.first + l.index;
    const Eigen::Quaterniond& a = c.rotations_[i];
    const double f = l.fraction;
    if (f == 0.0) return a;
    const PreparedClip::RotationPair& p = c.pairs_[i];
    double s0 = 1 - f, s1 = f;
    if (p.theta != 0) {
      const Eigen::Array2d s = TaylorSin2((1 - f) * p.theta, f * p.theta);
      s0 = s[0] * p.inv_sin;
      s1 = s[1] * p.inv_sin;
    }
    return Eigen::Quaterniond(s0 * a.coeffs() + (p.sign * s1) * c.rotations_[i + 1].coeffs());
  };
  for (const PreparedClip::JointPlan& p : c.plan_) {
    output->rigid[p.joint] = p.rigid >= 0 ? c.rigids_[p.rigid] : Rigid(rotation(p.rotation), vector(p.translation));
    output->scale[p.joint] = vector(p.scale);
  }
  SampleWeightTracks(c.weight_tracks_, t, *output);
  return true;
}

}  // namespace arview::anim
