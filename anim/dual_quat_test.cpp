#include "anim/blend.h"
#include "anim/dual_quat.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace arview::anim {
namespace {

DualQuatd RandomDq(std::mt19937& rng, double max_t = 2.0) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> u(-max_t, max_t);
  Eigen::Quaterniond r(n(rng), n(rng), n(rng), n(rng));
  return DualQuatd::FromRotationTranslation(r.normalized(), Eigen::Vector3d(u(rng), u(rng), u(rng)));
}

double Distance(const DualQuatd& a, const DualQuatd& b) {
  // Sign-independent distance between two unit dual quaternions.
  const DualQuatd bb = AlignedWith(b, a);
  return std::sqrt((a.real().coeffs() - bb.real().coeffs()).squaredNorm() +
                   (a.dual().coeffs() - bb.dual().coeffs()).squaredNorm());
}

TEST(DualQuat, MatrixAgreement) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const DualQuatd a = RandomDq(rng), b = RandomDq(rng);
    const Eigen::Vector3d p(0.3, -1.2, 2.5);
    EXPECT_LT((a.ToMatrix() * b.ToMatrix() - (a * b).ToMatrix()).norm(), 1e-12);
    const Eigen::Vector4d ph = a.ToMatrix() * p.homogeneous();
    EXPECT_LT((ph.head<3>() - a.TransformPoint(p)).norm(), 1e-12);
    EXPECT_LT(Distance(DualQuatd::FromMatrix(a.ToMatrix()), a), 1e-12);
    EXPECT_TRUE((a * b).IsUnit(1e-12));
    EXPECT_LT((a * a.Conjugate()).ToMatrix().isIdentity(1e-12) ? 0.0 : 1.0, 0.5);
  }
}

TEST(DualQuat, Eq1TranslationRoundTrip) {
  const Eigen::Quaterniond r(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Vector3d t(4, -5, 6);
  const DualQuatd q = DualQuatd::FromRotationTranslation(r, t);
  EXPECT_LT((q.Translation() - t).norm(), 1e-12);
  EXPECT_LT(q.Rotation().angularDistance(r), 1e-12);
}

TEST(DualQuat, LogExpInverse) {
  std::mt19937 rng(2);
  for (int i = 0; i < 500; ++i) {
    const DualQuatd q = RandomDq(rng);
    EXPECT_LT(Distance(DualQuatd::Exp(q.Log()), q), 1e-10) << i;
  }
  // Near-identity rotations and pure translations go through the series branches.
  for (double angle : {0.0, 1e-9, 1e-6, 1e-5, 2e-4, 1e-3}) {
    const DualQuatd q = DualQuatd::FromRotationTranslation(
        Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY())), Eigen::Vector3d(1, 2, 3));
    EXPECT_LT(Distance(DualQuatd::Exp(q.Log()), q), 1e-12) << angle;
  }
  // Rotation close to π.
  const DualQuatd q = DualQuatd::FromRotationTranslation(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI - 1e-7, Eigen::Vector3d::UnitX())), Eigen::Vector3d(0, 1, 0));
  EXPECT_LT(Distance(DualQuatd::Exp(q.Log()), q), 1e-9);
}

TEST(DualQuat, FloatLogExp) {
  std::mt19937 rng(3);
  for (int i = 0; i < 100; ++i) {
    const DualQuatf q = RandomDq(rng).cast<float>();
    const DualQuatf r = DualQuatf::Exp(q.Log());
    EXPECT_LT((r.ToMatrix() - q.ToMatrix()).norm(), 1e-4f);
  }
}

TEST(DualQuat, ScLerpEndpointsAndConstantSpeed) {
  std::mt19937 rng(4);
  const DualQuatd a = RandomDq(rng), b = RandomDq(rng);
  EXPECT_LT(Distance(ScLerp(a, b, 0.0), a), 1e-12);
  EXPECT_LT(Distance(ScLerp(a, b, 1.0), b), 1e-10);
  EXPECT_LT(Distance(ScLerp(a, -b, 0.5), ScLerp(a, b, 0.5)), 1e-12);
  // Equal steps of t give equal screw displacements.
  const DualLog<double> l1 = (ScLerp(a, b, 0.2).Conjugate() * ScLerp(a, b, 0.4)).Log();
  const DualLog<double> l2 = (ScLerp(a, b, 0.6).Conjugate() * ScLerp(a, b, 0.8)).Log();
  EXPECT_NEAR(l1.Norm(), l2.Norm(), 1e-10);
}

TEST(Blend, SingleWeightReturnsInput) {
  std::mt19937 rng(5);
  std::vector<DualQuatd> q = {RandomDq(rng), RandomDq(rng), RandomDq(rng)};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> w(3, 0.0);
    w[k] = 1.0;
    EXPECT_LT(Distance(Dlb<double>(q, w), q[k]), 1e-12);
    const DibResult<double> r = Dib<double>(q, w);
    EXPECT_TRUE(r.converged);
    EXPECT_LT(Distance(r.q, q[k]), 1e-12);
  }
}

TEST(Blend, DibTwoKeysEqualsScLerp) {
  std::mt19937 rng(6);
  for (int i = 0; i < 100; ++i) {
    std::vector<DualQuatd> q = {RandomDq(rng), RandomDq(rng)};
    if (i % 2) q[1] = -q[1];  // antipodal representative must not matter
    const double t = std::uniform_real_distribution<double>(0, 1)(rng);
    const std::vector<double> w = {1 - t, t};
    const DibResult<double> r = Dib<double>(q, w, {1e-13, 100});
    EXPECT_TRUE(r.converged);
    EXPECT_LT(Distance(r.q, ScLerp(q[0], q[1], t)), 1e-9) << i;
  }
}

TEST(Blend, FloatDibMatchesDouble) {
  std::mt19937 rng(11);
  for (int i = 0; i < 20; ++i) {
    std::vector<DualQuatd> q = {RandomDq(rng), RandomDq(rng), RandomDq(rng)};
    const std::vector<double> w = {0.2, 0.5, 0.3};
    std::vector<DualQuatf> qf;
    for (const auto& x : q) qf.push_back(x.cast<float>());
    const std::vector<float> wf = {0.2f, 0.5f, 0.3f};
    const DibResult<float> rf = Dib<float>(qf, wf, {1e-5f, 50});
    const DualQuatd rd = Dib<double>(q, w, {1e-12, 100}).q;
    EXPECT_LT((rf.q.ToMatrix().cast<double>() - rd.ToMatrix()).norm(), 1e-3) << i;
    EXPECT_LT((Dlb<float>(qf, wf).ToMatrix().cast<double>() - Dlb<double>(q, w).ToMatrix()).norm(), 1e-4) << i;
  }
}

TEST(Blend, DibCoordinateInvariance) {
  std::mt19937 rng(7);
  for (int i = 0; i < 50; ++i) {
    std::vector<DualQuatd> q(5);
    for (auto& x : q) x = RandomDq(rng);
    std::vector<double> w(5);
    double sum = 0;
    for (auto& x : w) sum += (x = std::uniform_real_distribution<double>(0.05, 1)(rng));
    for (auto& x : w) x /= sum;
    const DualQuatd m = RandomDq(rng);
    std::vector<DualQuatd> left(5), right(5);
    for (int k = 0; k < 5; ++k) {
      left[k] = m * q[k];
      right[k] = q[k] * m;
    }
    const DibOptions<double> opt{1e-12, 200};
    const DualQuatd b = Dib<double>(q, w, opt).q;
    EXPECT_LT(Distance(Dib<double>(left, w, opt).q, m * b), 1e-9) << i;
    EXPECT_LT(Distance(Dib<double>(right, w, opt).q, b * m), 1e-9) << i;
  }
}

TEST(Blend, AntipodalInputsDoNotCancel) {
  const DualQuatd a = DualQuatd::FromRotationTranslation(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(1, 0, 0));
  std::vector<DualQuatd> q = {a, -a};
  std::vector<double> w = {0.5, 0.5};
  EXPECT_LT(Distance(Dlb<double>(q, w), a), 1e-12);
  EXPECT_LT(Distance(Dib<double>(q, w).q, a), 1e-12);
}

TEST(Blend, DibIterationCapReportsNonConvergence) {
  std::mt19937 rng(8);
  std::vector<DualQuatd> q(4);
  for (auto& x : q) x = RandomDq(rng, 10.0);
  const std::vector<double> w = {0.25, 0.25, 0.25, 0.25};
  const DibResult<double> r = Dib<double>(q, w, {1e-300, 3});
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_TRUE(r.q.IsUnit(1e-12));
}

TEST(Blend, DlbIsUnitAndCloseToDib) {
  std::mt19937 rng(9);
  for (int i = 0; i < 50; ++i) {
    std::vector<DualQuatd> q(3);
    const DualQuatd base = RandomDq(rng);
    for (auto& x : q) {
      // Nearby transforms: DLB is a good approximation there.
      DualLog<double> l;
      l.real = Eigen::Vector3d::Random() * 0.1;
      l.dual = Eigen::Vector3d::Random() * 0.1;
      x = base * DualQuatd::Exp(l);
    }
    const std::vector<double> w = {0.2, 0.3, 0.5};
    const DualQuatd d = Dlb<double>(q, w);
    EXPECT_TRUE(d.IsUnit(1e-12));
    EXPECT_LT(Distance(d, Dib<double>(q, w, {1e-12, 100}).q), 1e-3);
  }
}

}  // namespace
}  // namespace arview::anim
