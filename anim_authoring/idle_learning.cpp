#include "anim_authoring/idle_learning.h"

#include "anim/blending_params.h"
#include "anim/pose.h"
#include "base/stats.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

namespace arview::authoring {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

Eigen::Matrix3d RootParentLinear(const anim::Skeleton& sk) { return sk.root_parent.block<3, 3>(0, 0); }

// The fastest joint's angular speed (rad/s) per frame step of each training sequence, the
// postures read as the synthesizer reads them (exponential maps of the first `joints` triples).
std::vector<double> FastestJointSpeeds(const PostureSequences& data) {
  auto rotation = [](const Eigen::VectorXd& v, int k) {
    const Eigen::Vector3d r = v.segment<3>(3 * k);
    const double a = r.norm();
    return a < 1e-12 ? Eigen::Quaterniond::Identity() : Eigen::Quaterniond(Eigen::AngleAxisd(a, r / a));
  };
  std::vector<double> speeds;
  const int joints = static_cast<int>(data.joints.size());
  for (const auto& seq : data.segments)
    for (std::size_t f = 1; f < seq.size(); ++f) {
      double fastest = 0;
      for (int k = 0; k < joints; ++k)
        fastest = std::max(fastest, rotation(seq[f - 1], k).angularDistance(rotation(seq[f], k)) * data.rate);
      speeds.push_back(fastest);
    }
  return speeds;
}

Eigen::Quaterniond RootParentRotation(const anim::Skeleton& sk) {
  Eigen::Matrix3d r = RootParentLinear(sk);
  for (int c = 0; c < 3; ++c) r.col(c).normalize();
  return Eigen::Quaterniond(r).normalized();
}

Eigen::Vector3d LogMap(Eigen::Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::AngleAxisd aa(q.normalized());
  return aa.angle() * aa.axis();
}

// Joint → model rotations (root_parent's rotation included).
void ModelRotations(const anim::Skeleton& sk, const anim::LocalPose& p, std::vector<Eigen::Quaterniond>& out) {
  const Eigen::Quaterniond rp = RootParentRotation(sk);
  out.resize(sk.size());
  for (int j = 0; j < sk.size(); ++j)
    out[j] = ((sk.parents[j] < 0 ? rp : out[sk.parents[j]]) * p.rigid[j].Rotation()).normalized();
}

// Model-space extent of the rest pose along `up`.
double RestHeight(const anim::Skeleton& sk, const Eigen::Vector3d& up) {
  anim::LocalPose rest = anim::LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  anim::MustRun(anim::LocalToModelJob{&sk, &rest, model}, "rest height");
  double lo = 1e300, hi = -1e300;
  for (const auto& m : model) {
    const double h = up.dot(m.block<3, 1>(0, 3));
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  return hi > lo ? hi - lo : 1.0;
}

// A chain: from `first`, following the child whose subtree is largest, up to `count` joints.
std::vector<int> ChainFrom(const anim::Skeleton& sk, int first, int count) {
  std::vector<int> chain;
  for (int j = first; j >= 0 && static_cast<int>(chain.size()) < count;) {
    chain.push_back(j);
    int next = -1;
    std::size_t best = 0;
    for (int c = j + 1; c < sk.size(); ++c)
      if (sk.parents[c] == j) {
        const std::size_t size = anim::Subtree(sk, c).size();
        if (next < 0 || size > best) next = c, best = size;
      }
    j = next;
  }
  return chain;
}

struct Chains {
  int root = 0;
  std::vector<int> spine, neck, arm[2], leg[2];
};

Chains FindChains(const anim::Skeleton& sk) {
  Chains c;
  const int neck = anim::NeckJoint(sk);
  if (neck >= 0) {
    for (int j = sk.parents[neck]; j >= 0 && sk.parents[j] >= 0; j = sk.parents[j]) c.spine.insert(c.spine.begin(), j);
    // Neck to head: the path to the first descendant named head, else two joints.
    int head = -1;
    for (int j : anim::Subtree(sk, neck))
      if (Lower(sk.names[j]).find("head") != std::string::npos) {
        head = j;
        break;
      }
    if (head >= 0)
      for (int j = head; j >= 0; j = sk.parents[j]) {
        c.neck.insert(c.neck.begin(), j);
        if (j == neck) break;
      }
    else
      c.neck = ChainFrom(sk, neck, 2);
  }
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 0;
    if (int a = anim::ArmRoot(sk, left); a >= 0) c.arm[side] = ChainFrom(sk, a, 4);
    if (int l = anim::LegRoot(sk, left); l >= 0) {
      if (Lower(sk.names[l]).find("hipjoint") != std::string::npos) l = ChainFrom(sk, l, 2).back();  // CMU's zero-length helper
      c.leg[side] = ChainFrom(sk, l, 4);
    }
  }
  return c;
}

// Pairs of a character chain and a data chain: proportional along spines, aligned at the end
// (hand ↔ hand, foot ↔ foot) along limbs, whose extra joints are at the start (clavicle).
void PairChains(const std::vector<int>& ch, const std::vector<int>& da, bool align_end, std::vector<std::pair<int, int>>& out) {
  if (ch.empty() || da.empty()) return;
  const int m = static_cast<int>(ch.size()), n = static_cast<int>(da.size());
  for (int k = 0; k < m; ++k) {
    int d;
    if (align_end) {
      d = n - m + k;
      if (d < 0) continue;
    } else {
      d = m == 1 ? (n - 1) / 2 : static_cast<int>(std::lround(double(k) * (n - 1) / (m - 1)));
    }
    out.emplace_back(ch[k], da[d]);
  }
}

struct Frames {
  std::vector<anim::LocalPose> poses;  // data poses at `rate`
};

// The rotation taking the data's model frame (up +Y, forward +Z, as BVH files are) to the
// character's (its up and forward).
Eigen::Quaterniond DataToCharacter(const Eigen::Vector3d& forward, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d f = (forward - forward.dot(u) * u).normalized();
  Eigen::Matrix3d character, data;
  character << f, u, f.cross(u);
  data << Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ().cross(Eigen::Vector3d::UnitY());
  return Eigen::Quaterniond(character * data.transpose()).normalized();
}

struct Retargeter {
  Retargeter(const anim::Skeleton& character, const anim::Skeleton& data) : ch(character), da(data) {}
  const anim::Skeleton& ch;
  const anim::Skeleton& da;
  std::vector<std::pair<int, int>> pairs;  // character joint, data joint
  bool identity = false;                   // the character's own clips
  Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  double height_ratio = 1;
  std::vector<Eigen::Quaterniond> data_mean;  // per data joint, model space
  Eigen::Vector3d data_root_mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Quaterniond> ch_rest_model;

  std::vector<int> Joints() const {
    std::vector<int> j;
    for (auto [c, d] : pairs) j.push_back(c);
    return j;
  }

  // Posture vector of one data frame: rotations of the mapped character joints relative to
  // their rest, then the root's offset in the root's parent frame.
  Eigen::VectorXd Posture(const anim::LocalPose& data_pose, std::vector<Eigen::Quaterniond>& g) const {
    const int m = static_cast<int>(pairs.size());
    Eigen::VectorXd v(3 * m + 3);
    if (identity) {
      for (int k = 0; k < m; ++k)
        v.segment<3>(3 * k) = LogMap(ch.rest[pairs[k].first].rotation.conjugate() * data_pose.rigid[pairs[k].first].Rotation());
      v.tail<3>() = data_pose.rigid[0].Translation() - ch.rest[0].translation;
      return v;
    }
    ModelRotations(da, data_pose, g);
    // Character model rotations: rest with the data's change about its mean, in character axes.
    std::vector<Eigen::Quaterniond> cm(ch.size());
    std::vector<int> source(ch.size(), -1);
    for (auto [c, d] : pairs) source[c] = d;
    const Eigen::Quaterniond rp = RootParentRotation(ch);
    for (int j = 0; j < ch.size(); ++j) {
      const Eigen::Quaterniond parent = ch.parents[j] < 0 ? rp : cm[ch.parents[j]];
      if (source[j] >= 0) {
        const Eigen::Quaterniond delta = a * (g[source[j]] * data_mean[source[j]].conjugate()) * a.conjugate();
        cm[j] = (delta * ch_rest_model[j]).normalized();
      } else {
        cm[j] = (parent * ch.rest[j].rotation).normalized();
      }
    }
    for (int k = 0; k < m; ++k) {
      const int j = pairs[k].first;
      const Eigen::Quaterniond parent = ch.parents[j] < 0 ? rp : cm[ch.parents[j]];
      v.segment<3>(3 * k) = LogMap(ch.rest[j].rotation.conjugate() * (parent.conjugate() * cm[j]));
    }
    const Eigen::Vector3d data_root = da.root_parent.block<3, 3>(0, 0) * data_pose.rigid[0].Translation();
    const Eigen::Vector3d offset_model = a * (data_root - data_root_mean) * height_ratio;
    v.tail<3>() = RootParentLinear(ch).inverse() * offset_model;
    return v;
  }
};

using Stillest = PostureSequences::Stillest;

// Standing runs of a clip sampled at `rate`: root speed and joint speed below the limits.
std::vector<std::pair<int, int>> StandingRuns(const anim::Skeleton& da, const std::vector<anim::LocalPose>& poses,
                                              const std::vector<int>& data_joints, double rate, double data_height,
                                              const IdleLearningOptions& o, Stillest& stillest, const std::string& name) {
  std::vector<bool> still(poses.size(), false);
  std::vector<double> root_speeds(poses.size(), 0.0), joint_speeds(poses.size(), 0.0);
  std::vector<Eigen::Quaterniond> prev, cur;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    ModelRotations(da, poses[i - 1], prev);
    ModelRotations(da, poses[i], cur);
    const Eigen::Matrix3d rp = da.root_parent.block<3, 3>(0, 0);
    const double root_speed =
        (rp * (poses[i].rigid[0].Translation() - poses[i - 1].rigid[0].Translation())).norm() * rate / data_height;
    double joint_speed = 0;
    for (int d : data_joints) joint_speed = std::max(joint_speed, prev[d].angularDistance(cur[d]) * rate);
    still[i] = root_speed < o.max_root_speed && joint_speed < o.max_joint_speed;
    root_speeds[i] = root_speed;
    joint_speeds[i] = joint_speed;
  }
  std::vector<std::pair<int, int>> runs;
  const int min_frames = static_cast<int>(std::ceil(o.min_segment_seconds * rate));
  for (int b = 1; b + min_frames <= static_cast<int>(poses.size()); ++b) {
    const double r = *std::max_element(root_speeds.begin() + b, root_speeds.begin() + b + min_frames);
    const double j = *std::max_element(joint_speeds.begin() + b, joint_speeds.begin() + b + min_frames);
    const double score = std::max(r / o.max_root_speed, j / o.max_joint_speed);
    if (score < stillest.score) {
      char at[64];
      std::snprintf(at, sizeof(at), " at %.1f s", b / rate);
      stillest = {r, j, score, name + at};
    }
  }
  for (std::size_t i = 0; i < still.size();) {
    if (!still[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < still.size() && still[j]) ++j;
    if (static_cast<int>(j - i) >= min_frames) runs.emplace_back(static_cast<int>(i), static_cast<int>(j));
    i = j;
  }
  return runs;
}

std::vector<anim::LocalPose> Resample(const anim::Skeleton& sk, const anim::Clip& clip, double rate) {
  std::vector<anim::LocalPose> poses;
  const int n = std::max(1, static_cast<int>(std::floor(clip.duration * rate)) + 1);
  for (int i = 0; i < n; ++i) {
    poses.emplace_back(sk.size());
    anim::MustRun(anim::SamplingJob{&sk, &clip, i / rate, false, &poses.back()}, "idle learning");
  }
  return poses;
}

Eigen::Quaterniond MeanRotation(const std::vector<Eigen::Quaterniond>& qs) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const auto& q : qs) sum += (q.coeffs().dot(qs.front().coeffs()) < 0 ? -1.0 : 1.0) * q.coeffs();
  return Eigen::Quaterniond(sum).normalized();
}

// k-means on 2-D points, seeded k-means++ initialisation; returns the label of each point.
std::vector<int> KMeans(const std::vector<Eigen::Vector2d>& p, int k, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Vector2d> centre{p[rng() % p.size()]};
  while (static_cast<int>(centre.size()) < k) {
    std::vector<double> d2(p.size());
    double total = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      double best = 1e300;
      for (const auto& c : centre) best = std::min(best, (p[i] - c).squaredNorm());
      total += d2[i] = best;
    }
    if (!(total > 0)) break;
    double x = static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0) * total;
    std::size_t pick = 0;
    for (; pick + 1 < p.size() && x >= d2[pick]; ++pick) x -= d2[pick];
    centre.push_back(p[pick]);
  }
  std::vector<int> label(p.size(), 0);
  for (int iteration = 0; iteration < 50; ++iteration) {
    bool changed = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
      int best = 0;
      for (std::size_t c = 1; c < centre.size(); ++c)
        if ((p[i] - centre[c]).squaredNorm() < (p[i] - centre[best]).squaredNorm()) best = static_cast<int>(c);
      changed = changed || best != label[i];
      label[i] = best;
    }
    std::vector<Eigen::Vector2d> sum(centre.size(), Eigen::Vector2d::Zero());
    std::vector<int> count(centre.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) sum[label[i]] += p[i], ++count[label[i]];
    for (std::size_t c = 0; c < centre.size(); ++c)
      if (count[c]) centre[c] = sum[c] / count[c];
    if (!changed && iteration > 0) break;
  }
  // Drop empty clusters: relabel densely.
  std::vector<int> remap(centre.size(), -1);
  int next = 0;
  for (int& l : label) {
    if (remap[l] < 0) remap[l] = next++;
    l = remap[l];
  }
  return label;
}

// Indices of the extrema of a lightly smoothed signal (moving average over `window` frames).
std::vector<int> Extrema(const std::vector<double>& x, int window) {
  const int n = static_cast<int>(x.size());
  std::vector<double> s(n);
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    int count = 0;
    for (int k = std::max(0, i - window); k <= std::min(n - 1, i + window); ++k) sum += x[k], ++count;
    s[i] = sum / count;
  }
  std::vector<int> out;
  for (int i = 1; i + 1 < n; ++i)
    if ((s[i] > s[i - 1] && s[i] >= s[i + 1]) || (s[i] < s[i - 1] && s[i] <= s[i + 1])) out.push_back(i);
  return out;
}

// The shape of the recorded segment c[from..to], normalised to run from 0 to 1: what synthesis
// replays, scaled to the swing it joins. Empty (synthesis then uses a cosine) when the swing is
// too small to carry a shape: the signal strays more than a quarter of the swing outside it
// (a near-flat stretch between two barely different extrema).
std::vector<double> SegmentShape(const std::vector<double>& c, int from, int to) {
  const double rise = c[to] - c[from];
  if (to - from < 2 || rise == 0) return {};
  std::vector<double> shape;
  for (int f = from; f <= to; ++f) {
    const double x = (c[f] - c[from]) / rise;
    if (x < -0.25 || x > 1.25) return {};
    shape.push_back(x);
  }
  shape.front() = 0;
  shape.back() = 1;
  return shape;
}

}  // namespace

std::vector<std::pair<int, int>> HumanoidJointPairs(const anim::Skeleton& character, const anim::Skeleton& data,
                                                    const std::map<std::string, std::string>& overrides) {
  const Chains c = FindChains(character), d = FindChains(data);
  std::vector<std::pair<int, int>> pairs{{c.root, d.root}};
  PairChains(c.spine, d.spine, false, pairs);
  PairChains(c.neck, d.neck, false, pairs);
  for (int s = 0; s < 2; ++s) {
    PairChains(c.arm[s], d.arm[s], true, pairs);
    PairChains(c.leg[s], d.leg[s], true, pairs);
  }
  for (const auto& [data_name, character_name] : overrides) {
    const int dj = data.Find(data_name), cj = character.Find(character_name);
    if (dj < 0) throw anim::Error("idle.joint_map: no joint '" + data_name + "' in the motion data");
    if (cj < 0) throw anim::Error("idle.joint_map: no joint '" + character_name + "' in the character");
    std::erase_if(pairs, [&](const auto& p) { return p.first == cj; });
    pairs.emplace_back(cj, dj);
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end(), [](auto& a, auto& b) { return a.first == b.first; }), pairs.end());
  return pairs;
}

namespace {

// The retargeting of one source onto the character: the humanoid joint pairs (or every joint
// for the character's own clips), the axes and the height ratio.
Retargeter MakeRetargeter(const anim::Skeleton& ch, const IdleSource& src, const IdleLearningOptions& o) {
  const anim::Skeleton& da = src.data->skeleton;
  Retargeter r(ch, da);
  r.identity = src.is_character;
  if (r.identity) {
    for (int j = 0; j < ch.size(); ++j) r.pairs.emplace_back(j, j);
    return r;
  }
  r.pairs = HumanoidJointPairs(ch, da, o.joint_map);
  if (r.pairs.size() < 6)
    throw anim::Error(src.data->source + ": only " + std::to_string(r.pairs.size()) +
                " joints map onto the character by name (give idle.joint_map)");
  r.a = DataToCharacter(o.forward, o.up);
  r.height_ratio = RestHeight(ch, o.up) / RestHeight(da, Eigen::Vector3d::UnitY());
  anim::LocalPose rest = anim::LocalPose::Rest(ch);
  ModelRotations(ch, rest, r.ch_rest_model);
  return r;
}

// The postures of the frames in `runs` ([begin, end) frame ranges of `poses`), retargeted about
// the data's mean posture over those frames, one sequence per run.
std::vector<std::vector<Eigen::VectorXd>> RunPostures(Retargeter& r, const std::vector<anim::LocalPose>& poses,
                                                      const std::vector<std::pair<int, int>>& runs) {
  const anim::Skeleton& da = r.da;
  std::vector<std::vector<Eigen::Quaterniond>> per_joint(da.size());
  Eigen::Vector3d root_sum = Eigen::Vector3d::Zero();
  int count = 0;
  std::vector<Eigen::Quaterniond> g;
  for (auto [b, e] : runs)
    for (int i = b; i < e; ++i) {
      ModelRotations(da, poses[i], g);
      for (int j = 0; j < da.size(); ++j) per_joint[j].push_back(g[j]);
      root_sum += da.root_parent.block<3, 3>(0, 0) * poses[i].rigid[0].Translation();
      ++count;
    }
  r.data_mean.resize(da.size());
  for (int j = 0; j < da.size(); ++j) r.data_mean[j] = MeanRotation(per_joint[j]);
  r.data_root_mean = root_sum / count;
  std::vector<std::vector<Eigen::VectorXd>> out;
  for (auto [b, e] : runs) {
    std::vector<Eigen::VectorXd> seq;
    for (int i = b; i < e; ++i) seq.push_back(r.Posture(poses[i], g));
    out.push_back(std::move(seq));
  }
  return out;
}

}  // namespace

PostureSequences TrainingPostures(const anim::Skeleton& ch, const std::vector<IdleSource>& sources, const IdleLearningOptions& o,
                                  double rate) {
  PostureSequences out;
  out.rate = rate;
  out.root = 0;
  for (const IdleSource& src : sources) {
    const anim::Skeleton& da = src.data->skeleton;
    Retargeter r = MakeRetargeter(ch, src, o);
    if (out.joints.empty()) out.joints = r.Joints();
    else if (out.joints != r.Joints())
      throw anim::Error(src.data->source + ": maps onto other joints than the first motion source; learn from one kind of rig");
    std::vector<int> data_joints;
    for (auto [c, d] : r.pairs) data_joints.push_back(d);
    const double data_height = RestHeight(da, Eigen::Vector3d::UnitY());
    for (const anim::Clip* clip : src.clips) {
      const std::vector<anim::LocalPose> poses = Resample(da, *clip, rate);
      // The character's own clips are taken whole: the scene names them as idle material.
      const auto runs = src.is_character ? std::vector<std::pair<int, int>>{{0, static_cast<int>(poses.size())}}
                                         : StandingRuns(da, poses, data_joints, rate, data_height, o, out.stillest, src.data->source);
      if (runs.empty()) continue;
      for (auto& seq : RunPostures(r, poses, runs)) out.segments.push_back(std::move(seq));
    }
  }
  return out;
}

std::vector<Eigen::VectorXd> ClipPostures(const anim::Skeleton& ch, const IdleSource& source, const anim::Clip& clip,
                                          const IdleLearningOptions& o, double rate, std::vector<int>* joints) {
  Retargeter r = MakeRetargeter(ch, source, o);
  if (joints) *joints = r.Joints();
  const std::vector<anim::LocalPose> poses = Resample(source.data->skeleton, clip, rate);
  return RunPostures(r, poses, {{0, static_cast<int>(poses.size())}}).front();
}

anim::IdleModel LearnIdleModel(const anim::Skeleton& ch, const std::vector<IdleSource>& sources, const IdleLearningOptions& o,
                         IdleLearningReport* report) {
  IdleLearningReport rep;
  for (const IdleSource& s : sources)
    for (const anim::Clip* c : s.clips) rep.source_seconds += c->duration;
  const PostureSequences data = TrainingPostures(ch, sources, o);
  std::string names;
  for (const IdleSource& s : sources) names += (names.empty() ? "" : ", ") + s.data->source;
  if (data.segments.empty()) {
    char buf[512];
    std::snprintf(buf, sizeof(buf),
                  ": no standing segment of %.3g s or more (root below %.3g heights/s, joints below %.3g rad/s) to learn idle "
                  "motion from; the stillest is %s (root %.3g heights/s, fastest joint %.3g rad/s)",
                  o.min_segment_seconds, o.max_root_speed, o.max_joint_speed, data.stillest.where.c_str(), data.stillest.root,
                  data.stillest.joint);
    throw anim::Error(names + buf);
  }
  const int dims = static_cast<int>(data.segments.front().front().size());
  int frames = 0;
  for (const auto& seg : data.segments) frames += static_cast<int>(seg.size());
  Eigen::MatrixXd x(frames, dims);
  int row = 0;
  for (const auto& seg : data.segments)
    for (const auto& v : seg) x.row(row++) = v.transpose();
  anim::IdleModel m;
  m.joints = data.joints;
  m.root = data.root;
  m.mean = x.colwise().mean().transpose();
  m.min = x.colwise().minCoeff().transpose();
  m.max = x.colwise().maxCoeff().transpose();
  const Eigen::MatrixXd centred = x.rowwise() - m.mean.transpose();
  const Eigen::MatrixXd cov = centred.transpose() * centred / std::max(1, frames - 1);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  const int k = std::min(o.components, dims);
  m.eigenvalues.resize(k);
  m.components.resize(dims, k);
  const double total = eig.eigenvalues().sum();
  double kept = 0;
  for (int i = 0; i < k; ++i) {
    m.eigenvalues[i] = std::max(0.0, eig.eigenvalues()[dims - 1 - i]);
    m.components.col(i) = eig.eigenvectors().col(dims - 1 - i);
    kept += m.eigenvalues[i];
  }
  // Per component: extrema (interval, value), k-means, transitions.
  const int window = std::max(1, static_cast<int>(std::lround(0.05 * data.rate)));  // ±50 ms
  for (int i = 0; i < k; ++i) {
    std::vector<anim::IdleModel::Extremum> ex;
    std::vector<std::pair<int, int>> links;  // consecutive extrema (indices into ex)
    for (const auto& seg : data.segments) {
      std::vector<double> c(seg.size());
      for (std::size_t f = 0; f < seg.size(); ++f) c[f] = m.components.col(i).dot(seg[f] - m.mean);
      // The segment's ends bound its first and last intervals (a slow component may turn only
      // once or never inside a short segment).
      std::vector<int> idx = Extrema(c, window);
      if (idx.empty() || idx.front() != 0) idx.insert(idx.begin(), 0);
      if (idx.back() != static_cast<int>(c.size()) - 1) idx.push_back(static_cast<int>(c.size()) - 1);
      for (std::size_t e = 1; e < idx.size(); ++e) {
        if (e > 1) links.emplace_back(static_cast<int>(ex.size()) - 1, static_cast<int>(ex.size()));
        ex.push_back({(idx[e] - idx[e - 1]) / data.rate, c[idx[e]], c[idx[e]] - c[idx[e - 1]],
                      SegmentShape(c, idx[e - 1], idx[e])});
      }
    }
    anim::IdleModel::ComponentChain chain;
    if (ex.empty()) {
      throw anim::Error(names + ": component " + std::to_string(i + 1) + " has no extrema in the standing segments");
    }
    double mean_dt = 0, mean_v = 0;
    for (const auto& e : ex) mean_dt += e.dt, mean_v += e.value;
    mean_dt /= ex.size();
    mean_v /= ex.size();
    double sd_dt = 0, sd_v = 0;
    for (const auto& e : ex) sd_dt += (e.dt - mean_dt) * (e.dt - mean_dt), sd_v += (e.value - mean_v) * (e.value - mean_v);
    sd_dt = std::sqrt(sd_dt / ex.size()) + 1e-12;
    sd_v = std::sqrt(sd_v / ex.size()) + 1e-12;
    std::vector<Eigen::Vector2d> pts;
    for (const auto& e : ex) pts.emplace_back(e.dt / sd_dt, e.value / sd_v);
    const int clusters = std::max(1, std::min(o.clusters, static_cast<int>(ex.size()) / 4));
    const std::vector<int> label = KMeans(pts, clusters, 1000 + i);
    const int used = *std::max_element(label.begin(), label.end()) + 1;
    chain.clusters.resize(used);
    chain.transitions.assign(used, std::vector<double>(used, 0.0));
    chain.frequency.assign(used, 0.0);
    for (std::size_t e = 0; e < ex.size(); ++e) {
      chain.clusters[label[e]].push_back(ex[e]);
      chain.frequency[label[e]] += 1;
    }
    for (auto [a, b] : links) chain.transitions[label[a]][label[b]] += 1;
    m.chains.push_back(std::move(chain));
    rep.extrema.push_back(static_cast<int>(ex.size()));
    rep.clusters.push_back(used);
  }
  m.training_frames = frames;
  m.speed_limit = arview::Percentile(FastestJointSpeeds(data), 0.99);
  m.speed_step = 1 / data.rate;
  m.training_seconds = frames / data.rate;
  rep.frames = frames;
  rep.seconds = m.training_seconds;
  rep.segments = static_cast<int>(data.segments.size());
  rep.mapped_joints = static_cast<int>(data.joints.size());
  rep.variance_explained = total > 0 ? kept / total : 0;
  if (report) *report = rep;
  m.Check(ch.size());
  return m;
}

std::string IdleLearningReport::Summary() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "%d standing segments, %.1f s of %.1f s (%d frames at 30 Hz), %d joints mapped, %zu components explain %.1f%% "
                "of the variance",
                segments, seconds, source_seconds, frames, mapped_joints, extrema.size(), 100 * variance_explained);
  std::string s = buf;
  s += "; extrema/clusters per component:";
  for (std::size_t i = 0; i < extrema.size(); ++i) s += " " + std::to_string(extrema[i]) + "/" + std::to_string(clusters[i]);
  return s;
}

}  // namespace arview::authoring
