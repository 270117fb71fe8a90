#include "anim/view_adaptive.h"

#include "anim/morph.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <type_traits>

namespace arview::anim {
namespace {

template <class V>
bool SameKeys(const std::vector<Key<V>>& a, const std::vector<Key<V>>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].time != b[i].time) return false;
    if constexpr (std::is_same_v<V, Eigen::Quaterniond>) {
      if (a[i].value.coeffs() != b[i].value.coeffs()) return false;
    } else if (a[i].value != b[i].value) {
      return false;
    }
  }
  return true;
}

bool SameTrack(const JointTrack& a, const JointTrack& b) {
  return SameKeys(a.rotation, b.rotation) && SameKeys(a.translation, b.translation) && SameKeys(a.scale, b.scale);
}

bool SameWeightTracks(const std::vector<WeightTrack>& a, const std::vector<WeightTrack>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].target != b[i].target || !SameKeys(a[i].weights, b[i].weights)) return false;
  return true;
}

// A clip's time for `t` looped into [0, duration), as PreparedSamplingJob loops it.
double Looped(double t, double duration) {
  if (duration <= 0) return 0;
  t = std::fmod(t, duration);
  return t < 0 ? t + duration : t;
}

std::vector<Eigen::Vector3d> Directions(const std::vector<ViewAdaptiveKey>& keys) {
  std::vector<Eigen::Vector3d> dirs;
  for (const ViewAdaptiveKey& k : keys) dirs.push_back(k.viewpoint);
  return dirs;
}

}  // namespace

ViewAdaptiveBlend::ViewAdaptiveBlend(std::shared_ptr<const Skeleton> skeleton, std::vector<ViewAdaptiveKey> keys,
                                     const ViewAdaptiveOptions& options)
    : skeleton_(std::move(skeleton)), keys_(std::move(keys)), options_(options), sphere_(Directions(keys_), options.weights) {
  const int K = key_count();
  if (K > BlendingJob::kMaxInputs)
    throw Error(std::to_string(K) + " keys; at most " + std::to_string(BlendingJob::kMaxInputs));
  for (const ViewAdaptiveKey& k : keys_)
    if (!k.clip || static_cast<int>(k.clip->tracks.size()) != skeleton_->size())
      throw Error("key clip '" + (k.clip ? k.clip->name : std::string("?")) + "' does not fit the skeleton");
  // The shared phase runs at the mean length of the distinct animated key clips.
  std::set<const Clip*> distinct;
  double total = 0;
  for (const ViewAdaptiveKey& k : keys_)
    if (k.clip->duration > 0 && distinct.insert(k.clip.get()).second) total += k.clip->duration;
  shared_period_ = distinct.empty() ? 0.0 : total / double(distinct.size());
  // A joint is shared when every key clip has its track and the clips have one length (so that
  // every key is sampled at the same time: KeyTime).
  bool same_length = true;
  for (const ViewAdaptiveKey& k : keys_) same_length = same_length && k.clip->duration == keys_[0].clip->duration;
  for (int j = 0; j < skeleton_->size(); ++j) {
    bool same = same_length;
    for (int k = 1; same && k < K; ++k) same = SameTrack(keys_[k].clip->tracks[j], keys_[0].clip->tracks[j]);
    (same ? shared_joints_ : varying_joints_).push_back(j);
  }
  // The face (morph target weights) is blended apart from the joints (BlendFace): the prepared
  // clips sample joints only.
  const int targets = skeleton_->morph_target_count();
  for (const ViewAdaptiveKey& k : keys_) {
    face_keyed_ = face_keyed_ || (targets > 0 && !k.clip->weight_tracks.empty());
    face_varies_ = face_varies_ || !same_length || !SameWeightTracks(k.clip->weight_tracks, keys_[0].clip->weight_tracks);
    if (!WeightTracksFit(k.clip->weight_tracks, targets, 0))
      throw Error("key clip '" + k.clip->name + "' keys a morph target the skeleton does not have");
  }
  face_.Resize(0, targets);
  Clip joints_only = *keys_[0].clip;
  joints_only.weight_tracks.clear();
  if (!shared_joints_.empty())
    shared_ = std::make_unique<PreparedClip>(*skeleton_, joints_only, options_.nlerp_sampling, shared_joints_);
  if (!varying_joints_.empty())
    for (const ViewAdaptiveKey& k : keys_) prepared_.emplace_back(*skeleton_, *k.clip, options_.nlerp_sampling, varying_joints_);
  weights_.assign(K, 0.0);
  key_poses_.assign(K, LocalPose(skeleton_->size()));
  active_ptrs_.assign(K, nullptr);
  active_weights_.assign(K, 0.0);
}

double ViewAdaptiveBlend::KeyTime(int key, double t) const {
  const double d = keys_[key].clip->duration;
  if (options_.phase == PhaseMode::kIndependent || shared_period_ <= 0 || d <= 0) return t;
  double phase = std::fmod(t / shared_period_, 1.0);
  if (phase < 0) phase += 1.0;
  return phase * d;
}

void ViewAdaptiveBlend::BlendFace(double t, LocalPose& out) {
  out.morph_keyed = false;
  if (!face_keyed_ || out.morph.empty()) return;
  if (!face_varies_) {  // every key keys the same weights: the blend is any key's
    SampleWeightTracks(keys_[0].clip->weight_tracks, Looped(KeyTime(0, t), keys_[0].clip->duration), out);
    return;
  }
  // As DLB blends the joints: each key's weights, by its view weight (normalised); a key without
  // weight tracks is the rest (every weight 0), as a key without a joint's track is its rest.
  double total = 0;
  for (double w : weights_) total += w;
  if (!(total > 0)) return;
  std::fill(out.morph.begin(), out.morph.end(), 0.f);
  for (int k = 0; k < key_count(); ++k) {
    const std::vector<WeightTrack>& tracks = keys_[k].clip->weight_tracks;
    if (weights_[k] <= 0 || tracks.empty()) continue;
    SampleWeightTracks(tracks, Looped(KeyTime(k, t), keys_[k].clip->duration), face_);
    const float f = static_cast<float>(weights_[k] / total);
    for (std::size_t i = 0; i < out.morph.size(); ++i) out.morph[i] += f * face_.morph[i];
  }
  out.morph_keyed = true;
}

bool ViewAdaptiveBlend::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  if (!std::isfinite(t)) t = 0;
  sphere_.Weights(inputs.viewpoint, weights_);
  if (out.size() != skeleton_->size()) return false;
  if (!out.morph.empty() && static_cast<int>(out.morph.size()) != skeleton_->morph_target_count()) return false;
  if (!SampleJoints(t, out)) return false;
  BlendFace(t, out);  // after the joints: sampling them marks the weights unkeyed
  return true;
}

bool ViewAdaptiveBlend::SampleJoints(double t, LocalPose& out) {
  converged_ = true;
  max_iterations_ = 0;
  if (shared_ && !PreparedSamplingJob{shared_.get(), KeyTime(0, t), true, &out}.Run()) return false;
  if (varying_joints_.empty()) return true;
  int active = 0;
  for (int k = 0; k < key_count(); ++k) {
    if (weights_[k] <= 0) continue;
    if (!PreparedSamplingJob{&prepared_[k], KeyTime(k, t), true, &key_poses_[k]}.Run()) return false;
    active_ptrs_[active] = &key_poses_[k];
    active_weights_[active] = weights_[k];
    ++active;
  }
  BlendingJob blend;
  blend.inputs = std::span<const LocalPose* const>(active_ptrs_.data(), active);
  blend.weights = std::span<const double>(active_weights_.data(), active);
  blend.method = options_.blend;
  blend.dib = options_.dib;
  blend.output = &out;
  blend.joints = varying_joints_;
  blend.converged = &converged_;
  blend.max_iterations = &max_iterations_;
  return blend.Run();
}

}  // namespace arview::anim
