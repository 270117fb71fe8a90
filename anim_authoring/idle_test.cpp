// Idle motion learned from the CMU motion capture (assimp-testmodels) mapped onto
// BCN_Epileptic: what the data supports, and the statistics of a 10-minute synthesized stream.

#include "anim_authoring/idle_learning.h"
#include "anim_authoring/import.h"
#include "base/stats.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace arview::authoring {
namespace {

const char* kBvhDir = "/usr/share/assimp/models/BVH";
const char* kBcn = "/usr/share/assimp/models/X/BCN_Epileptic.X";

struct Learned {
  anim::Character fox;
  std::vector<IdleSource> sources;
  IdleLearningOptions options;
  anim::IdleModel model;
  IdleLearningReport report;
};

// The Fox's own idle clip (Survey: it stands and looks around), taken whole.
std::unique_ptr<Learned> Learn() {
  auto l = std::make_unique<Learned>();
  l->fox = LoadCharacter(testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"));
  l->sources.push_back({&l->fox, {l->fox.FindClip("Survey")}, true});
  l->model = LearnIdleModel(l->fox.skeleton, l->sources, l->options, &l->report);
  return l;
}

// Per-frame angular speeds (rad/s) of every animated joint between consecutive postures.
void Speeds(const std::vector<Eigen::VectorXd>& seq, int joints, double rate, std::vector<double>& frame_max) {
  for (std::size_t f = 1; f < seq.size(); ++f) {
    double worst = 0;
    for (int k = 0; k < joints; ++k) {
      auto q = [&](const Eigen::VectorXd& v) {
        const Eigen::Vector3d r = v.segment<3>(3 * k);
        const double a = r.norm();
        return a < 1e-12 ? Eigen::Quaterniond::Identity() : Eigen::Quaterniond(Eigen::AngleAxisd(a, r / a));
      };
      worst = std::max(worst, q(seq[f - 1]).angularDistance(q(seq[f])) * rate);
    }
    frame_max.push_back(worst);
  }
}

TEST(Idle, HumanoidMapPairsCmuWithBcnEpileptic) {
  ARVIEW_REQUIRE_DATA_PATH(kBcn, "Debian package assimp-testmodels");
  const anim::Character bcn = LoadCharacter(kBcn), cmu = LoadCharacter(std::string(kBvhDir) + "/01_01.bvh");
  const auto pairs = HumanoidJointPairs(bcn.skeleton, cmu.skeleton);
  std::map<std::string, std::string> named;
  for (auto [c, d] : pairs) named[bcn.skeleton.names[c]] = cmu.skeleton.names[d];
  EXPECT_EQ(named["B_Hand_Left"], "LeftHand");
  EXPECT_EQ(named["B_ForeArm_Right"], "RightForeArm");
  EXPECT_EQ(named["B_Knee_Left"], "LeftLeg");
  EXPECT_EQ(named["B_Ankle_Right"], "RightFoot");
  EXPECT_EQ(named["B_Clavicle_Left"], "LeftShoulder");
  EXPECT_GE(pairs.size(), 20u);
  std::printf("[idle] %zu BCN_Epileptic joints mapped onto CMU 01_01\n", pairs.size());
}

TEST(Idle, TenMinuteStreamMatchesTheData) {
  ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox"), "../shared/data");
  const auto l = Learn();
  std::printf("[idle] Fox Survey: %s\n", l->report.Summary().c_str());
  const anim::IdleModel& m = l->model;
  auto skeleton = std::make_shared<const anim::Skeleton>(l->fox.skeleton);
  auto model = std::make_shared<const anim::IdleModel>(m);
  anim::IdleSynthesizer idle(skeleton, model, 7);
  const double rate = 30;
  const int frames = static_cast<int>(600 * rate);
  std::vector<Eigen::VectorXd> stream;
  stream.reserve(frames);
  anim::LocalPose pose(skeleton->size());
  for (int f = 0; f < frames; ++f) {
    ASSERT_TRUE(idle.Sample(f / rate, {}, pose));
    stream.push_back(idle.Posture(f / rate));
  }
  // Per-PC variance of the stream against the data's eigenvalue (issue 13: within a factor
  // 1.5), of the synthesized component values; printed also for the clamped postures projected
  // back (clamping each value into its range leaks into the tiny components: docs/anim.md).
  std::vector<Eigen::VectorXd> coefficients;
  anim::IdleSynthesizer walk(skeleton, model, 7);
  for (int f = 0; f < frames; ++f) coefficients.push_back(walk.Coefficients(f / rate));
  double worst_ratio = 1;
  int within = 0;
  for (int i = 0; i < m.component_count(); ++i) {
    double sum = 0, sum2 = 0, psum = 0, psum2 = 0;
    for (int f = 0; f < frames; ++f) {
      const double c = coefficients[f][i], p = m.components.col(i).dot(stream[f] - m.mean);
      sum += c, sum2 += c * c, psum += p, psum2 += p * p;
    }
    const double var = sum2 / frames - (sum / frames) * (sum / frames);
    const double pvar = psum2 / frames - (psum / frames) * (psum / frames);
    const double ratio = var / m.eigenvalues[i];
    std::printf("[idle] PC %d: data variance %.3g, synthesized %.3g (ratio %.2f), clamped postures %.3g (ratio %.2f)\n", i + 1,
                m.eigenvalues[i], var, ratio, pvar, pvar / m.eigenvalues[i]);
    worst_ratio = std::max(worst_ratio, std::max(ratio, 1 / ratio));
    within += ratio <= 1.5 && ratio >= 1 / 1.5;
    EXPECT_GT(var, 0) << "PC " << i + 1 << " never moves";
    EXPECT_LE(ratio, 1.5) << "PC " << i + 1;
    EXPECT_GE(ratio, 1 / 1.5) << "PC " << i + 1;
  }
  std::printf("[idle] %d of %d components within a factor 1.5 of the data's variance\n", within, m.component_count());
  // Every value within the data's range.
  for (const auto& p : stream)
    for (int d = 0; d < m.dims(); ++d) ASSERT_TRUE(p[d] >= m.min[d] && p[d] <= m.max[d]);
  // Per-frame angular speed against the data's 99th percentile (both at 30 Hz).
  const PostureSequences data = TrainingPostures(l->fox.skeleton, l->sources, l->options, rate);
  std::vector<double> data_speed, stream_speed;
  for (const auto& seg : data.segments) Speeds(seg, static_cast<int>(m.joints.size()), rate, data_speed);
  Speeds(stream, static_cast<int>(m.joints.size()), rate, stream_speed);
  const double data_p99 = arview::Percentile(data_speed, 0.99), stream_max = *std::max_element(stream_speed.begin(), stream_speed.end());
  const double stream_p99 = arview::Percentile(stream_speed, 0.99);
  std::printf("[idle] fastest joint per frame: data p99 %.3f rad/s (model limit %.3f); stream p99 %.3f, max %.3f rad/s; median data %.3f, "
              "stream %.3f rad/s; worst variance ratio %.2f\n",
              data_p99, m.speed_limit, stream_p99, stream_max, arview::Percentile(data_speed, 0.5), arview::Percentile(stream_speed, 0.5),
              worst_ratio);
  // Issue 13: the stream below the data's p99. The components are walked independently (as the
  // thesis does) and each new segment is stretched until all components together stay within
  // the data's p99 (anim/idle.h); without that the p99 was 1.650 against 1.621 on this clip.
  EXPECT_NEAR(m.speed_limit, data_p99, 1e-9);
  EXPECT_LT(stream_p99, data_p99);
  // Same seed, same stream; another seed, another.
  anim::IdleSynthesizer again(skeleton, model, 7), other(skeleton, model, 8);
  for (int f = 0; f < 300; f += 7) {
    EXPECT_EQ(again.Posture(f / rate), stream[f]);
  }
  EXPECT_GT((other.Posture(5.0) - stream[150]).norm(), 1e-6);
  // Sampling backwards replays from the seed: the same values.
  EXPECT_EQ(idle.Posture(2.0), stream[60]);
}

// What the CMU captures support: no standing segment (they jump, climb and turn); the error
// says how still their stillest second is.
TEST(Idle, CmuCapturesHoldNoStandingSegment) {
  ARVIEW_REQUIRE_DATA_PATH(kBcn, "Debian package assimp-testmodels");
  ARVIEW_REQUIRE_DATA_PATH(std::string(kBvhDir) + "/01_03.bvh", "Debian package assimp-testmodels");
  const anim::Character bcn = LoadCharacter(kBcn), cmu1 = LoadCharacter(std::string(kBvhDir) + "/01_01.bvh"),
                  cmu3 = LoadCharacter(std::string(kBvhDir) + "/01_03.bvh");
  try {
    LearnIdleModel(bcn.skeleton, {{&cmu1, {&cmu1.clips.front()}, false}, {&cmu3, {&cmu3.clips.front()}, false}}, {});
    FAIL() << "learned from jumping";
  } catch (const anim::Error& e) {
    std::printf("[idle] CMU 01_01 + 01_03 on BCN_Epileptic: %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("no standing segment"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("the stillest is"), std::string::npos);
  }
}

}  // namespace
}  // namespace arview::authoring
