#pragma once
// The view-adaptive blend (docs/method.md §1, Algorithm 2) as a runtime object: K key clips tied to
// key viewpoints, weighted by the current viewpoint (view_sphere.h) and blended joint by joint
// (DLB or DIB). Built once from clips already prepared (anim_authoring/ loads assets and
// generates look-at and gesture keys); sampled every frame without allocating. It is a
// Blendable (unbounded: it plays as long as it is scheduled), so a schedule can fade it in and
// out like any action; the viewpoint comes from FrameInputs.
//
//   ViewAdaptiveBlend blend(skeleton, keys, options);
//   if (!blend.Sample(t, {viewpoint}, pose)) ...;   blend.weights()[k]

#include "anim/blendable.h"
#include "anim/prepared_clip.h"
#include "anim/view_sphere.h"

#include <memory>
#include <span>
#include <vector>

namespace arview::anim {

enum class PhaseMode { kShared, kIndependent };

struct ViewAdaptiveKey {
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // unit, character frame
  std::shared_ptr<const Clip> clip;                       // keys may share clips
};

struct ViewAdaptiveOptions {
  ViewSphereOptions weights;
  BlendMethod blend = BlendMethod::kDlb;
  DibOptions<double> dib;
  PhaseMode phase = PhaseMode::kShared;
  bool nlerp_sampling = false;
};

class ViewAdaptiveBlend : public Blendable {
 public:
  // Throws Error when there are no keys, more than BlendingJob::kMaxInputs, or a clip does not
  // fit the skeleton.
  ViewAdaptiveBlend(std::shared_ptr<const Skeleton> skeleton, std::vector<ViewAdaptiveKey> keys,
                    const ViewAdaptiveOptions& options = {});

  double Duration() const override { return kUnbounded; }
  // Weights for inputs.viewpoint (a zero viewpoint: equal weights), every key with weight > 0
  // sampled at t (the shared phase or its own loop) and blended. The keys' morph target weights
  // (their clips' weight tracks) are blended with the same weights, linearly; a key without
  // weight tracks counts as every weight 0, and when no key has any the pose's weights are left
  // unkeyed (morph_keyed false: the layers below keep the face).
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return skeleton_->size(); }

  int key_count() const { return static_cast<int>(keys_.size()); }
  const ViewAdaptiveKey& key(int k) const { return keys_[k]; }
  const ViewSphere& view_sphere() const { return sphere_; }
  const ViewAdaptiveOptions& options() const { return options_; }
  // Of the last Sample (converged and max_iterations over the joints the keys disagree on: the
  // others are not blended).
  std::span<const double> weights() const { return weights_; }
  bool converged() const { return converged_; }
  int max_iterations() const { return max_iterations_; }

 private:
  double KeyTime(int key, double t) const;
  bool SampleJoints(double t, LocalPose& out);  // sampled and blended (DLB or DIB)
  void BlendFace(double t, LocalPose& out);     // the morph target weights, when a key keys them

  std::shared_ptr<const Skeleton> skeleton_;
  std::vector<ViewAdaptiveKey> keys_;
  ViewAdaptiveOptions options_;
  // Joints whose tracks are the same in every key clip (generated keys change only their chain:
  // BCN_Epileptic's look-at keys agree on 46 of 54 joints) are sampled once, from shared_, and not
  // blended: the blend of equal inputs is that input. The others are sampled per key, from
  // prepared_, and blended.
  std::vector<int> shared_joints_, varying_joints_;
  std::unique_ptr<PreparedClip> shared_;  // null when no joint is shared
  std::vector<PreparedClip> prepared_;    // per key, its varying joints (empty when none vary)
  ViewSphere sphere_;
  double shared_period_ = 0;
  std::vector<double> weights_;
  std::vector<LocalPose> key_poses_;
  // The face: whether a key clip has weight tracks, whether they differ between keys (or the
  // keys' lengths do), and one key's weights as sampled (joints: none).
  bool face_keyed_ = false, face_varies_ = false;
  LocalPose face_;
  std::vector<const LocalPose*> active_ptrs_;
  std::vector<double> active_weights_;
  bool converged_ = true;
  int max_iterations_ = 0;
};

}  // namespace arview::anim
