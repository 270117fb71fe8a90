#pragma once
// Per-frame animation jobs in ozz-animation's style: a plain struct of inputs and outputs,
// Validate() says whether they fit together, Run() validates then computes and returns false on
// invalid input ([[nodiscard]]: a skeleton/clip mismatch must not pass as a stale pose). Jobs
// never allocate: outputs are sized by the caller (LocalPose::Resize once).
//
//   LocalPose pose(skeleton.size());
//   if (!SamplingJob{&skeleton, &clip, time, /*loop=*/true, &pose}.Run()) ...;
//   std::vector<Eigen::Matrix4d> model(skeleton.size());
//   MustRun(LocalToModelJob{&skeleton, &pose, model}, "where");   // throws Error on failure
//   std::vector<Eigen::Matrix4f> skin(skeleton.size());
//   std::vector<DualQuatf> skin_dq(skeleton.size());
//   MustRun(SkinningMatricesJob{&skeleton, model, skin, skin_dq}, "where");   // upload to the GPU
//
// A pose is, per joint, the local rigid transform as a unit dual quaternion plus a scale
// (applied first, M = T·R·S); blending (BlendingJob) works on the dual quaternions and blends
// scales linearly.

#include "anim/blend.h"
#include "anim/character.h"

#include <span>
#include <string>
#include <vector>

namespace arview::anim {

struct LocalPose {
  std::vector<DualQuatd> rigid;
  std::vector<Eigen::Vector3d> scale;
  // One weight per morph target (Skeleton::morph_targets), or empty: a pose sized for joints
  // alone, which samplers fill without the face. `morph_keyed` says whether the object that
  // wrote the pose set the weights (a clip with weight tracks, a schedule playing one); the
  // frame blender blends the weights of those that did, and leaves the others out.
  std::vector<float> morph;
  bool morph_keyed = false;

  LocalPose() = default;
  explicit LocalPose(int joints, int morph_targets = 0) { Resize(joints, morph_targets); }
  void Resize(int joints, int morph_targets = 0);
  int size() const { return static_cast<int>(rigid.size()); }
  // The skeleton's rest pose.
  static LocalPose Rest(const Skeleton& skeleton);
};

// Samples `clip` at `time` seconds: linear translation and scale, slerp rotation between keys.
// `loop` wraps time into [0, duration); otherwise it is clamped.
// `nlerp` replaces slerp by normalised linear interpolation of the rotation keys: about 2.5x
// faster sampling, exact at keys and midpoints; between them, on the test assets' clips, within
// 0.79° of slerp on the Fox and 0.02° on CesiumMan, BCN_Epileptic and CMU 01_01 (import_test).
// What samples one clip every frame prepares it once instead (prepared_clip.h: the same pose to
// rounding, without the per-channel key search or slerp's acos).
struct SamplingJob {
  const Skeleton* skeleton = nullptr;
  const Clip* clip = nullptr;
  double time = 0;
  bool loop = true;
  LocalPose* output = nullptr;
  bool nlerp = false;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

enum class BlendMethod { kDlb, kDib };

// Blends K poses joint by joint with the given convex weights (Eq. 3). At most kMaxInputs;
// weights must be finite, non-negative and not all zero.
struct BlendingJob {
  static constexpr int kMaxInputs = 64;
  std::span<const LocalPose* const> inputs;
  std::span<const double> weights;
  BlendMethod method = BlendMethod::kDlb;
  DibOptions<double> dib;
  LocalPose* output = nullptr;
  // The joints to blend (empty: every joint); the others of `output` are left as they are.
  std::span<const int> joints;
  // Filled when not null: for DIB, whether every joint blended converged and the most iterations
  // any took.
  bool* converged = nullptr;
  int* max_iterations = nullptr;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

// Local poses → model-space matrices (root_parent · … · parent · local).
struct LocalToModelJob {
  const Skeleton* skeleton = nullptr;
  const LocalPose* input = nullptr;
  std::span<Eigen::Matrix4d> output;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

// LocalToModelJob for some joints only: `joints` increasing, each one's parent listed before it
// or already holding its model matrix in `output` (JointChain gives a set closed under parents);
// the other entries of `output` are left as they are. Each listed joint gets the matrix a full
// LocalToModelJob gives it, bit for bit (the Animator poses the eyes from the chain to the head).
struct JointsToModelJob {
  const Skeleton* skeleton = nullptr;
  const LocalPose* input = nullptr;
  std::span<const int> joints;
  std::span<Eigen::Matrix4d> output;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

// `joints` and all their ancestors, increasing: what a JointsToModelJob must compute for the model
// matrices of `joints` alone (allocates: build it once). Throws Error for a joint out of range.
std::vector<int> JointChain(const Skeleton& skeleton, std::span<const int> joints);

// Model-space joint matrices → skinning matrices (model · inverse_bind), as float matrices and,
// when `dual_quats` is not empty, as dual quaternions of their rigid part (for DQ skinning; a
// non-rigid skinning matrix loses its scale there: see RigidSkinning()).
struct SkinningMatricesJob {
  const Skeleton* skeleton = nullptr;
  std::span<const Eigen::Matrix4d> model;
  std::span<Eigen::Matrix4f> matrices;
  std::span<DualQuatf> dual_quats;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

// Whether every skinning matrix is rigid (rotation + translation) to `tolerance`; DQ skinning
// is exact only then.
bool RigidSkinning(std::span<const Eigen::Matrix4f> matrices, float tolerance = 1e-3f);

// CPU skinning of one mesh (Kavan et al. 2007 for DQS). Outputs have mesh.vertex_count()
// entries; `normals_out` may be empty.
enum class SkinningMethod { kLinear, kDualQuaternion };
struct SkinningJob {
  const Mesh* mesh = nullptr;
  SkinningMethod method = SkinningMethod::kLinear;
  std::span<const Eigen::Matrix4f> matrices;  // for kLinear
  std::span<const DualQuatf> dual_quats;      // for kDualQuaternion
  std::span<Eigen::Vector3f> positions_out;
  std::span<Eigen::Vector3f> normals_out;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

// Runs a job whose inputs the caller built to fit (sizes fixed at construction): a false Run()
// is then a programming error (a skeleton, clip or buffer that disagrees), reported as an Error
// naming `what` instead of leaving a stale pose. Costs one branch on the per-frame path.
template <class Job>
void MustRun(const Job& job, const char* what) {
  if (!job.Run()) throw Error(std::string(what) + ": animation job inputs disagree (skeleton, clip or buffer sizes)");
}

}  // namespace arview::anim
