#include "anim/pose.h"

#include "anim/morph.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace arview::anim {
namespace {

// Index i of the last key with time ≤ t and the fraction toward key i+1.
template <class V>
std::pair<std::size_t, double> Locate(const std::vector<Key<V>>& keys, double t) {
  if (t <= keys.front().time) return {0, 0.0};
  if (t >= keys.back().time) return {keys.size() - 1, 0.0};
  const auto it = std::upper_bound(keys.begin(), keys.end(), t, [](double x, const Key<V>& k) { return x < k.time; });
  const std::size_t i = static_cast<std::size_t>(it - keys.begin()) - 1;
  const double span = keys[i + 1].time - keys[i].time;
  return {i, span > 0 ? (t - keys[i].time) / span : 0.0};
}

Eigen::Vector3d SampleVec(const std::vector<Key<Eigen::Vector3d>>& keys, double t, const Eigen::Vector3d& rest) {
  if (keys.empty()) return rest;
  const auto [i, f] = Locate(keys, t);
  if (f == 0.0) return keys[i].value;
  return (1 - f) * keys[i].value + f * keys[i + 1].value;
}

Eigen::Quaterniond SampleRot(const std::vector<Key<Eigen::Quaterniond>>& keys, double t, const Eigen::Quaterniond& rest,
                             bool nlerp) {
  if (keys.empty()) return rest;
  const auto [i, f] = Locate(keys, t);
  if (f == 0.0) return keys[i].value;
  if (!nlerp) return keys[i].value.slerp(f, keys[i + 1].value);  // Eigen's slerp takes the short way
  const Eigen::Vector4d a = keys[i].value.coeffs();
  Eigen::Vector4d b = keys[i + 1].value.coeffs();
  if (a.dot(b) < 0) b = -b;
  return Eigen::Quaterniond((1 - f) * a + f * b);  // normalised by the caller
}

bool Affine(const Eigen::Matrix4d& m) { return m(3, 0) == 0 && m(3, 1) == 0 && m(3, 2) == 0 && m(3, 3) == 1; }

// a · b for affine a and b (bottom rows 0 0 0 1): the top three rows only, 36 multiplications
// instead of Eigen's 64 for a general 4×4 product. The bottom row is set (the column sums would
// give −0 for +0 where a column of b is negative).
Eigen::Matrix4d AffineProduct(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  Eigen::Matrix4d m;
  for (int c = 0; c < 4; ++c) m.col(c) = a.col(0) * b(0, c) + a.col(1) * b(1, c) + a.col(2) * b(2, c);
  m.col(3) += a.col(3);
  m.row(3) << 0, 0, 0, 1;
  return m;
}

}  // namespace

void LocalPose::Resize(int joints, int morph_targets) {
  rigid.assign(joints, DualQuatd());
  scale.assign(joints, Eigen::Vector3d::Ones());
  morph.assign(morph_targets, 0.f);
  morph_keyed = false;
}

LocalPose LocalPose::Rest(const Skeleton& skeleton) {
  LocalPose p(skeleton.size(), skeleton.morph_target_count());
  for (int j = 0; j < skeleton.size(); ++j) {
    p.rigid[j] = skeleton.rest[j].Rigid();
    p.scale[j] = skeleton.rest[j].scale;
  }
  return p;
}

bool SamplingJob::Validate() const {
  return skeleton && clip && output && std::isfinite(time) && output->size() == skeleton->size() &&
         static_cast<int>(clip->tracks.size()) == skeleton->size() &&
         WeightTracksFit(clip->weight_tracks, skeleton->morph_target_count(), output->morph.size());
}

bool SamplingJob::Run() const {
  if (!Validate()) return false;
  double t = time;
  if (clip->duration <= 0) t = 0;
  else if (loop) {
    t = std::fmod(t, clip->duration);
    if (t < 0) t += clip->duration;
  } else t = std::clamp(t, 0.0, clip->duration);
  for (int j = 0; j < skeleton->size(); ++j) {
    const JointTrack& tr = clip->tracks[j];
    const Transform& rest = skeleton->rest[j];
    output->rigid[j] = DualQuatd::FromRotationTranslation(SampleRot(tr.rotation, t, rest.rotation, nlerp),
                                                          SampleVec(tr.translation, t, rest.translation));
    output->scale[j] = SampleVec(tr.scale, t, rest.scale);
  }
  SampleWeightTracks(clip->weight_tracks, t, *output);
  return true;
}

bool BlendingJob::Validate() const {
  if (!output || inputs.empty() || inputs.size() != weights.size() || inputs.size() > std::size_t(kMaxInputs)) return false;
  double sum = 0;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (!inputs[k] || inputs[k]->size() != output->size() || !(weights[k] >= 0) || !std::isfinite(weights[k])) return false;
    sum += weights[k];
  }
  for (int j : joints)
    if (j < 0 || j >= output->size()) return false;
  return sum > 0;
}

bool BlendingJob::Run() const {
  if (!Validate()) return false;
  const std::size_t K = inputs.size();
  std::array<DualQuatd, kMaxInputs> q;
  bool all_converged = true;
  int worst = 0;
  const int n = joints.empty() ? output->size() : static_cast<int>(joints.size());
  for (int i = 0; i < n; ++i) {
    const int j = joints.empty() ? i : joints[i];
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < K; ++k) {
      q[k] = inputs[k]->rigid[j];
      s += weights[k] * inputs[k]->scale[j];
    }
    const std::span<const DualQuatd> qs(q.data(), K);
    if (method == BlendMethod::kDlb) {
      output->rigid[j] = Dlb<double>(qs, weights);
    } else {
      const DibResult<double> r = Dib<double>(qs, weights, dib);
      output->rigid[j] = r.q;
      all_converged = all_converged && r.converged;
      worst = std::max(worst, r.iterations);
    }
    output->scale[j] = s;
  }
  if (converged) *converged = all_converged;
  if (max_iterations) *max_iterations = worst;
  return true;
}

namespace {

// Joint j's model matrix from its parent's (already in `output`) and its local transform.
void JointToModel(const Skeleton& skeleton, const LocalPose& input, int j, bool affine, std::span<Eigen::Matrix4d> output) {
  Eigen::Matrix4d local = input.rigid[j].ToMatrix();
  local.block<3, 3>(0, 0) *= input.scale[j].asDiagonal();
  const int p = skeleton.parents[j];
  const Eigen::Matrix4d& parent = p < 0 ? skeleton.root_parent : output[p];
  output[j] = affine ? AffineProduct(parent, local) : Eigen::Matrix4d(parent * local);
}

}  // namespace

bool LocalToModelJob::Validate() const {
  return skeleton && input && input->size() == skeleton->size() && output.size() == std::size_t(skeleton->size());
}

bool LocalToModelJob::Run() const {
  if (!Validate()) return false;
  // Every local matrix is affine, and so is every model matrix when root_parent is.
  const bool affine = Affine(skeleton->root_parent);
  for (int j = 0; j < skeleton->size(); ++j) JointToModel(*skeleton, *input, j, affine, output);
  return true;
}

bool JointsToModelJob::Validate() const {
  if (!LocalToModelJob{skeleton, input, output}.Validate()) return false;
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i] < 0 || joints[i] >= skeleton->size() || (i > 0 && joints[i] <= joints[i - 1])) return false;
  return true;
}

bool JointsToModelJob::Run() const {
  if (!Validate()) return false;
  const bool affine = Affine(skeleton->root_parent);
  for (int j : joints) JointToModel(*skeleton, *input, j, affine, output);
  return true;
}

std::vector<int> JointChain(const Skeleton& skeleton, std::span<const int> joints) {
  std::vector<bool> wanted(skeleton.size(), false);
  for (int j : joints) {
    if (j < 0 || j >= skeleton.size())
      throw Error("joint chain: joint " + std::to_string(j) + " out of range (" + std::to_string(skeleton.size()) + " joints)");
    for (int a = j; a >= 0 && !wanted[a]; a = skeleton.parents[a]) wanted[a] = true;
  }
  std::vector<int> chain;
  for (int j = 0; j < skeleton.size(); ++j)
    if (wanted[j]) chain.push_back(j);
  return chain;
}

bool SkinningMatricesJob::Validate() const {
  const std::size_t n = skeleton ? skeleton->size() : 0;
  return skeleton && model.size() == n && matrices.size() == n && (dual_quats.empty() || dual_quats.size() == n);
}

bool SkinningMatricesJob::Run() const {
  if (!Validate()) return false;
  for (int j = 0; j < skeleton->size(); ++j) {
    const Eigen::Matrix4d& inverse_bind = skeleton->inverse_bind[j];
    const Eigen::Matrix4d m = Affine(model[j]) && Affine(inverse_bind) ? AffineProduct(model[j], inverse_bind)
                                                                        : Eigen::Matrix4d(model[j] * inverse_bind);
    matrices[j] = m.cast<float>();
    if (!dual_quats.empty()) {
      // Rotation from the normalised columns (cheaper than an SVD, exact for rigid and for
      // uniformly scaled matrices).
      Eigen::Matrix3d r = m.block<3, 3>(0, 0);
      for (int c = 0; c < 3; ++c) r.col(c).normalize();
      dual_quats[j] = DualQuatd::FromRotationTranslation(Eigen::Quaterniond(r), m.block<3, 1>(0, 3)).cast<float>();
    }
  }
  return true;
}

bool RigidSkinning(std::span<const Eigen::Matrix4f> matrices, float tolerance) {
  for (const auto& m : matrices) {
    const Eigen::Matrix3f a = m.block<3, 3>(0, 0);
    if (!(a.transpose() * a).isIdentity(tolerance)) return false;
  }
  return true;
}

bool SkinningJob::Validate() const {
  if (!mesh) return false;
  const std::size_t n = mesh->positions.size();
  if (positions_out.size() != n || (!normals_out.empty() && normals_out.size() != n)) return false;
  if (mesh->joints.size() != n || mesh->weights.size() != n) return false;
  const std::size_t joints = method == SkinningMethod::kLinear ? matrices.size() : dual_quats.size();
  for (const auto& js : mesh->joints)
    for (auto j : js)
      if (j >= joints) return false;
  return true;
}

bool SkinningJob::Run() const {
  if (!Validate()) return false;
  const std::size_t n = mesh->positions.size();
  const bool with_normals = !normals_out.empty();
  for (std::size_t v = 0; v < n; ++v) {
    const auto& js = mesh->joints[v];
    const Eigen::Vector4f& ws = mesh->weights[v];
    if (method == SkinningMethod::kLinear) {
      Eigen::Matrix4f m = ws[0] * matrices[js[0]];
      for (int i = 1; i < 4; ++i)
        if (ws[i] != 0) m += ws[i] * matrices[js[i]];
      positions_out[v] = m.block<3, 3>(0, 0) * mesh->positions[v] + m.block<3, 1>(0, 3);
      if (with_normals) normals_out[v] = (m.block<3, 3>(0, 0) * mesh->normals[v]).normalized();
    } else {
      // Kavan et al. 2007: blend the dual quaternions (signs aligned with the first), normalise.
      const DualQuatf& pivot = dual_quats[js[0]];
      Eigen::Vector4f r = ws[0] * pivot.real().coeffs(), d = ws[0] * pivot.dual().coeffs();
      for (int i = 1; i < 4; ++i) {
        if (ws[i] == 0) continue;
        const DualQuatf& q = dual_quats[js[i]];
        const float w = q.RealDot(pivot) < 0 ? -ws[i] : ws[i];
        r += w * q.real().coeffs();
        d += w * q.dual().coeffs();
      }
      const DualQuatf b = DualQuatf(Eigen::Quaternionf(r), Eigen::Quaternionf(d)).Normalized();
      positions_out[v] = b.TransformPoint(mesh->positions[v]);
      if (with_normals) normals_out[v] = b.TransformVector(mesh->normals[v]);
    }
  }
  return true;
}

}  // namespace arview::anim
