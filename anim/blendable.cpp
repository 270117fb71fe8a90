#include "anim/blendable.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

namespace arview::anim {
namespace {

void Require(bool ok, const std::string& what) {
  if (!ok) throw Error(what);
}

double Finite(double t) { return std::isfinite(t) ? t : 0.0; }

}  // namespace

namespace {

// Throws Error as PreparedClip does for a clip that does not fit, and for none at all.
PreparedClip PrepareClip(const std::shared_ptr<const Skeleton>& skeleton, const std::shared_ptr<const Clip>& clip, bool nlerp) {
  Require(skeleton && clip, "clip source: no skeleton or clip");
  return PreparedClip(*skeleton, *clip, nlerp);
}

}  // namespace

ClipSource::ClipSource(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const Clip> clip, bool nlerp)
    : skeleton_(std::move(skeleton)), clip_(std::move(clip)), prepared_(PrepareClip(skeleton_, clip_, nlerp)) {}

bool ClipSource::Sample(double t, const FrameInputs&, LocalPose& out) {
  return PreparedSamplingJob{&prepared_, Finite(t), /*loop=*/false, &out}.Run();
}

StaticPose::StaticPose(LocalPose pose, double duration) : pose_(std::move(pose)), duration_(duration) {
  Require(duration_ > 0, "static pose: duration must be positive");
}

bool StaticPose::Sample(double, const FrameInputs&, LocalPose& out) {
  if (out.size() != pose_.size()) return false;
  std::copy(pose_.rigid.begin(), pose_.rigid.end(), out.rigid.begin());
  std::copy(pose_.scale.begin(), pose_.scale.end(), out.scale.begin());
  return true;
}

TimeStretch::TimeStretch(BlendablePtr inner, double duration) : inner_(std::move(inner)), duration_(duration) {
  Require(inner_ && std::isfinite(inner_->Duration()) && inner_->Duration() > 0,
          "stretch: needs an object with a fixed, positive length");
  Require(std::isfinite(duration_) && duration_ > 0, "stretch: duration must be a positive number of seconds");
}

bool TimeStretch::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  return inner_->Sample(std::clamp(Finite(t), 0.0, duration_) * (inner_->Duration() / duration_), inputs, out);
}

Loop::Loop(BlendablePtr inner, int count) : inner_(std::move(inner)), count_(count) {
  Require(inner_ && std::isfinite(inner_->Duration()) && inner_->Duration() > 0,
          "loop: needs an object with a fixed, positive length");
}

double Loop::Duration() const { return count_ > 0 ? count_ * inner_->Duration() : kUnbounded; }

bool Loop::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  const double d = inner_->Duration();
  t = std::max(0.0, Finite(t));
  if (count_ > 0 && t >= Duration()) return inner_->Sample(d, inputs, out);  // the last frame
  return inner_->Sample(std::fmod(t, d), inputs, out);
}

Window::Window(BlendablePtr inner, double from, double to) : inner_(std::move(inner)), from_(from), to_(to) {
  Require(inner_ != nullptr, "window: no object");
  Require(std::isfinite(from_) && from_ >= 0 && to_ > from_ && to_ <= inner_->Duration(),
          "window: needs 0 <= from < to <= the object's length");
}

bool Window::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  return inner_->Sample(from_ + std::clamp(Finite(t), 0.0, to_ - from_), inputs, out);
}

namespace {

// The name with its side swapped, or "" when it carries no side marker.
std::string SwapSide(const std::string& n) {
  static const std::pair<const char*, const char*> words[] = {{"Left", "Right"}, {"left", "right"}, {"LEFT", "RIGHT"}};
  for (const auto& [a, b] : words) {
    if (auto at = n.find(a); at != std::string::npos) return n.substr(0, at) + b + n.substr(at + std::strlen(a));
    if (auto at = n.find(b); at != std::string::npos) return n.substr(0, at) + a + n.substr(at + std::strlen(b));
  }
  auto swap_letter = [](char c) { return c == 'L' ? 'R' : c == 'R' ? 'L' : c == 'l' ? 'r' : 'l'; };
  auto is_side = [](char c) { return c == 'L' || c == 'R' || c == 'l' || c == 'r'; };
  auto alpha = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; };
  // "_L", ".L" (ending or followed by a non-letter), "L_" (starting or after a non-letter).
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!is_side(n[i])) continue;
    const bool before_sep = i > 0 && (n[i - 1] == '_' || n[i - 1] == '.');
    const bool after_sep = i + 1 < n.size() && (n[i + 1] == '_' || n[i + 1] == '.');
    const bool before_edge = i == 0 || !alpha(n[i - 1]);
    const bool after_edge = i + 1 >= n.size() || !alpha(n[i + 1]);
    if ((before_sep && after_edge) || (after_sep && before_edge)) {
      std::string s = n;
      s[i] = swap_letter(n[i]);
      return s;
    }
  }
  // CMU: "LThumb", "RHipJoint".
  if (n.size() > 2 && (n[0] == 'L' || n[0] == 'R') && std::isupper(static_cast<unsigned char>(n[1])) &&
      std::islower(static_cast<unsigned char>(n[2]))) {
    std::string s = n;
    s[0] = swap_letter(n[0]);
    return s;
  }
  return {};
}

// Reflection of a rotation across the plane with unit normal n: S R S, with S = I − 2nnᵀ; for a
// quaternion (w, v): (w, −S v).
Eigen::Quaterniond Reflect(const Eigen::Quaterniond& q, const Eigen::Vector3d& n) {
  const Eigen::Vector3d v = q.vec();
  const Eigen::Vector3d sv = v - 2 * v.dot(n) * n;
  return Eigen::Quaterniond(q.w(), -sv.x(), -sv.y(), -sv.z());
}

Eigen::Vector3d ReflectPoint(const Eigen::Vector3d& p, const Eigen::Vector3d& n) { return p - 2 * p.dot(n) * n; }

}  // namespace

namespace {

// Per name, the index of the name with its side swapped (itself when there is none), kept only
// where the pair is symmetric.
std::vector<int> PartnersByName(const std::vector<std::string>& names) {
  const int n = static_cast<int>(names.size());
  std::vector<int> partner(n);
  for (int i = 0; i < n; ++i) {
    const std::string other = SwapSide(names[i]);
    const auto at = other.empty() ? names.end() : std::find(names.begin(), names.end(), other);
    partner[i] = at != names.end() ? static_cast<int>(at - names.begin()) : i;
  }
  for (int i = 0; i < n; ++i)
    if (partner[partner[i]] != i) partner[i] = i;
  return partner;
}

}  // namespace

std::vector<int> MirrorPartners(const Skeleton& sk) { return PartnersByName(sk.names); }

std::vector<int> MirrorTargetPartners(const Skeleton& sk) { return PartnersByName(sk.morph_targets); }

Mirror::Mirror(BlendablePtr inner, std::shared_ptr<const Skeleton> skeleton, const Eigen::Vector3d& lateral)
    : inner_(std::move(inner)), skeleton_(std::move(skeleton)) {
  Require(inner_ && skeleton_ && inner_->joint_count() == skeleton_->size(), "mirror: object and skeleton disagree");
  Require(lateral.norm() > 1e-9, "mirror: the lateral axis has zero length");
  // The plane's normal in the frame the root joints live in (before root_parent).
  Eigen::Matrix3d rp = skeleton_->root_parent.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) rp.col(c).normalize();
  n_ = (rp.transpose() * lateral).normalized();
  partner_ = MirrorPartners(*skeleton_);
  target_partner_ = MirrorTargetPartners(*skeleton_);
  const int n = skeleton_->size();
  source_.Resize(n, skeleton_->morph_target_count());
  model_rot_.assign(n, Eigen::Quaterniond::Identity());
  mirrored_rot_ = model_rot_;
  model_pos_.assign(n, Eigen::Vector3d::Zero());
  mirrored_pos_ = model_pos_;
  // Rest model rotations, and per joint the correction that makes the mirror of the rest the rest.
  std::vector<Eigen::Quaterniond> rest(n);
  for (int j = 0; j < n; ++j) {
    const int p = skeleton_->parents[j];
    rest[j] = (p < 0 ? Eigen::Quaterniond::Identity() : rest[p]) * skeleton_->rest[j].rotation.normalized();
  }
  correction_.resize(n);
  for (int j = 0; j < n; ++j) correction_[j] = (Reflect(rest[partner_[j]], n_).conjugate() * rest[j]).normalized();
}

bool Mirror::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  if (out.size() != skeleton_->size() || !inner_->Sample(t, inputs, source_)) return false;
  const Skeleton& sk = *skeleton_;
  for (int j = 0; j < sk.size(); ++j) {
    const int p = sk.parents[j];
    model_rot_[j] = (p < 0 ? Eigen::Quaterniond::Identity() : model_rot_[p]) * source_.rigid[j].Rotation();
  }
  for (int j = 0; j < sk.size(); ++j) mirrored_rot_[j] = Reflect(model_rot_[partner_[j]], n_) * correction_[j];
  for (int j = 0; j < sk.size(); ++j) {
    const int p = sk.parents[j];
    const Eigen::Quaterniond local =
        p < 0 ? mirrored_rot_[j] : Eigen::Quaterniond(mirrored_rot_[p].conjugate() * mirrored_rot_[j]);
    // Bones keep their own offsets (lengths unchanged); a root's displacement from rest is mirrored.
    Eigen::Vector3d translation = source_.rigid[j].Translation();
    if (p < 0) {
      const Eigen::Vector3d rest = sk.rest[j].translation;
      translation = rest + ReflectPoint(source_.rigid[partner_[j]].Translation() - rest, n_);
    }
    out.rigid[j] = DualQuatd::FromRotationTranslation(local, translation);
    out.scale[j] = source_.scale[partner_[j]];
  }
  // The face mirrored as the joints are: each target takes its partner's weight (eyeBlinkLeft
  // the inner object's eyeBlinkRight), a target without a side keeps its own.
  out.morph_keyed = source_.morph_keyed && out.morph.size() == source_.morph.size();
  if (out.morph_keyed)
    for (std::size_t i = 0; i < out.morph.size(); ++i) out.morph[i] = source_.morph[target_partner_[i]];
  return true;
}

GlobalTransform::GlobalTransform(BlendablePtr inner, std::shared_ptr<const Skeleton> skeleton, const DualQuatd& transform)
    : inner_(std::move(inner)), skeleton_(std::move(skeleton)), transform_(transform.Normalized()) {
  Require(inner_ && skeleton_ && inner_->joint_count() == skeleton_->size(), "transform: object and skeleton disagree");
}

bool GlobalTransform::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  if (!inner_->Sample(t, inputs, out)) return false;
  for (int j = 0; j < skeleton_->size(); ++j)
    if (skeleton_->parents[j] < 0) out.rigid[j] = transform_ * out.rigid[j];
  return true;
}

}  // namespace arview::anim
