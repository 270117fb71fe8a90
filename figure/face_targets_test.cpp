// The built-in figure's morph targets (issue 52): ARKit shapes, visemes and Ekman's expressions.

#include "figure/face_targets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "anim/morph.h"
#include "figure/humanoid.h"

namespace arview::figure {
namespace {

const anim::Character& Figure() {
  static const anim::Character c = MakeHumanoid();
  return c;
}

int Target(const char* name) {
  const int t = Figure().skeleton.FindMorphTarget(name);
  EXPECT_GE(t, 0) << name;
  return t;
}

const char* const kRequiredArkit[] = {"jawOpen",          "mouthClose",        "mouthFunnel",     "mouthPucker",
                                      "mouthSmileLeft",   "mouthSmileRight",   "mouthFrownLeft",  "mouthFrownRight",
                                      "mouthStretchLeft", "mouthStretchRight", "browInnerUp",     "browDownLeft",
                                      "browDownRight",    "cheekPuff",         "eyeSquintLeft",   "eyeSquintRight"};
const char* const kVisemes[] = {"viseme_sil", "viseme_PP", "viseme_FF", "viseme_TH", "viseme_DD", "viseme_kk", "viseme_CH", "viseme_SS",
                                "viseme_nn",  "viseme_RR", "viseme_aa", "viseme_E",  "viseme_ih", "viseme_oh", "viseme_ou"};

TEST(FigureTargets, TheFigureHasTheArkitTargetsAndTheFifteenVisemes) {
  const anim::Skeleton& sk = Figure().skeleton;
  for (const char* name : kRequiredArkit) EXPECT_GE(sk.FindMorphTarget(name), 0) << name;
  ASSERT_EQ(VisemeTargetNames().size(), std::size(kVisemes));
  for (std::size_t k = 0; k < std::size(kVisemes); ++k) {
    EXPECT_STREQ(VisemeTargetNames()[k], kVisemes[k]);
    EXPECT_GE(sk.FindMorphTarget(kVisemes[k]), 0) << kVisemes[k];
  }
  EXPECT_EQ(sk.morph_target_count(), static_cast<int>(ArkitTargetNames().size() + VisemeTargetNames().size()));
  EXPECT_NO_THROW(anim::CheckMorphTargets(Figure()));
}

// Every target moves some vertices, all of them on the head (skinned to Head or a joint under it,
// in front of the head's centre), by finite amounts under 2.5 cm; the meshes it moves are small.
TEST(FigureTargets, EveryTargetMovesOnlyFaceVerticesByFiniteAmounts) {
  const anim::Character& c = Figure();
  const int head = c.skeleton.Find("Head");
  Eigen::Vector3d head_at = Eigen::Vector3d::Zero();  // rest rotations are the identity: offsets add
  for (int j = head; j >= 0; j = c.skeleton.parents[j]) head_at += c.skeleton.rest[j].translation;
  std::vector<int> moved(c.skeleton.morph_target_count(), 0);
  std::set<std::string> meshes;
  for (const anim::Mesh& mesh : c.meshes)
    for (const anim::MeshMorph& m : mesh.morphs) {
      meshes.insert(mesh.name + " (" + std::to_string(mesh.vertex_count()) + ")");
      EXPECT_LE(mesh.vertex_count(), 600) << mesh.name;
      for (std::size_t i = 0; i < m.vertices.size(); ++i) {
        const std::uint32_t v = m.vertices[i];
        const std::string label = c.skeleton.morph_targets[m.target] + " on " + mesh.name + " vertex " + std::to_string(v);
        ASSERT_TRUE(m.position_deltas[i].allFinite()) << label;
        ASSERT_TRUE(m.normal_deltas[i].allFinite()) << label;
        EXPECT_LT(m.position_deltas[i].norm(), 0.025f) << label;
        for (int k = 0; k < 4; ++k) {
          if (mesh.weights[v][k] == 0) continue;
          const int j = mesh.joints[v][k];
          EXPECT_TRUE(j == head || c.skeleton.parents[j] == head) << label << " is skinned to " << c.skeleton.names[j];
        }
        const Eigen::Vector3d from_head = mesh.positions[v].cast<double>() - head_at;
        EXPECT_LT(from_head.norm(), 0.2) << label << ": away from the head";
        EXPECT_GT(from_head.z(), 0.02) << label << ": behind the face";
        moved[m.target] += m.position_deltas[i].norm() > 0;
      }
    }
  for (int t = 0; t < c.skeleton.morph_target_count(); ++t) EXPECT_GT(moved[t], 0) << c.skeleton.morph_targets[t];
  std::string list;
  for (const std::string& m : meshes) list += " " + m;
  std::printf("[targets] meshes the targets move (vertices):%s\n", list.c_str());
}

// The vertical clearance between the lips at the mouth's middle (the upper lip's lowest vertex
// minus the lower lip's highest, within 2 mm of the middle; negative where they overlap).
double LipGap(const std::vector<float>& weights) {
  const anim::Character& c = Figure();
  const int jaw = c.skeleton.Find("Jaw");
  for (const anim::Mesh& mesh : c.meshes) {
    if (mesh.name != "face_lips") continue;
    std::vector<Eigen::Vector3f> p, n;
    anim::ApplyMorphTargets(mesh, weights, p, n);
    float upper = 1e9f, lower = -1e9f;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (std::abs(p[v].x()) > 0.002f) continue;
      if (mesh.joints[v][0] == jaw) lower = std::max(lower, p[v].y());
      else upper = std::min(upper, p[v].y());
    }
    return upper - lower;
  }
  ADD_FAILURE() << "no face_lips mesh";
  return 0;
}

std::vector<float> Only(const char* name, float w = 1) {
  std::vector<float> weights(Figure().skeleton.morph_target_count(), 0.0f);
  weights[Target(name)] = w;
  return weights;
}

TEST(FigureTargets, PPClosesTheLipsAndJawOpenAndAaOpenThem) {
  const double rest = LipGap(Only("viseme_PP", 0)), pp = LipGap(Only("viseme_PP"));
  const double jaw = LipGap(Only("jawOpen")), aa = LipGap(Only("viseme_aa")), oh = LipGap(Only("viseme_oh"));
  std::vector<float> closed = Only("jawOpen");
  closed[Target("mouthClose")] = 1;
  const double jaw_closed = LipGap(closed);
  std::printf("[targets] lip gap: rest %.2f mm, PP %.2f mm, jawOpen %.2f mm, jawOpen+mouthClose %.2f mm, aa %.2f mm, oh %.2f mm\n",
              rest * 1e3, pp * 1e3, jaw * 1e3, jaw_closed * 1e3, aa * 1e3, oh * 1e3);
  EXPECT_LT(pp, 0.001);
  EXPECT_LT(pp, rest) << "PP presses the lips together";
  EXPECT_GT(jaw, 0.01);
  EXPECT_GT(aa, 0.01);
  EXPECT_GT(oh, 0.004);
  EXPECT_LT(jaw_closed, 0.001) << "mouthClose brings the lips back together over an open jaw";
}

// The visemes' jaw shares a speech layer turns the Jaw joint by (anim/face.h) are the jawOpen
// column of docs/figure.md's table, read from the targets themselves.
TEST(FigureTargets, TheVisemesJawSharesAreTheirJawOpenTerms) {
  const std::span<const float> shares = VisemeJawShares();
  ASSERT_EQ(shares.size(), VisemeTargetNames().size());
  const float table[] = {0, 0, 0.15f, 0.25f, 0.3f, 0.4f, 0.2f, 0.1f, 0.2f, 0.2f, 1, 0.45f, 0.3f, 0.6f, 0.25f};
  for (std::size_t v = 0; v < shares.size(); ++v) EXPECT_FLOAT_EQ(shares[v], table[v]) << VisemeTargetNames()[v];
  EXPECT_EQ(kJawOpenDegrees, 14);
}

// The sum of |delta| a target puts on the figure's left (+X) half of the face against its right.
std::pair<double, double> LeftRight(const char* name) {
  const int t = Target(name);
  double left = 0, right = 0;
  for (const anim::Mesh& mesh : Figure().meshes)
    for (const anim::MeshMorph& m : mesh.morphs)
      if (m.target == t)
        for (std::size_t i = 0; i < m.vertices.size(); ++i)
          (mesh.positions[m.vertices[i]].x() > 0 ? left : right) += m.position_deltas[i].norm();
  return {left, right};
}

TEST(FigureTargets, LeftAndRightTargetsMoveTheirOwnSide) {
  for (const char* stem : {"mouthSmile", "mouthFrown", "mouthStretch", "browDown", "eyeSquint"}) {
    const auto [ll, lr] = LeftRight((std::string(stem) + "Left").c_str());
    const auto [rl, rr] = LeftRight((std::string(stem) + "Right").c_str());
    EXPECT_GT(ll, 3 * lr) << stem << "Left";
    EXPECT_GT(rr, 3 * rl) << stem << "Right";
    EXPECT_NEAR(ll, rr, 0.02 * ll) << stem << ": the two sides mirror";
  }
}

TEST(FigureTargets, EachExpressionIsWeightsOfTheFiguresTargetsWithinZeroAndOne) {
  std::set<std::string> names;
  for (Expression e : kExpressions) {
    names.insert(ExpressionName(e));
    const std::vector<TargetWeight> full = ExpressionWeights(e, 1);
    ASSERT_FALSE(full.empty()) << ExpressionName(e);
    for (double intensity : {-1.0, 0.0, 0.3, 1.0, 2.0}) {
      const std::vector<TargetWeight> w = ExpressionWeights(e, intensity);
      ASSERT_EQ(w.size(), full.size());
      for (std::size_t k = 0; k < w.size(); ++k) {
        EXPECT_GE(Figure().skeleton.FindMorphTarget(w[k].target), 0) << ExpressionName(e) << " " << w[k].target;
        EXPECT_GE(w[k].weight, 0.0f) << ExpressionName(e) << " " << w[k].target;
        EXPECT_LE(w[k].weight, 1.0f) << ExpressionName(e) << " " << w[k].target;
        EXPECT_FLOAT_EQ(w[k].weight, full[k].weight * static_cast<float>(std::clamp(intensity, 0.0, 1.0)));
      }
    }
  }
  EXPECT_EQ(names, (std::set<std::string>{"happy", "sad", "angry", "surprised", "afraid", "disgusted"}));
}

}  // namespace
}  // namespace arview::figure
