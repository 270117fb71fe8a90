#include "synth/orbit_walk.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace arview::synth {
namespace {

constexpr double kTwoPi = 2 * M_PI;
constexpr double kDeg = M_PI / 180;
// Lap 2 slows down near the close approach to `kSlowest` of its mean angular speed (a
// Gaussian dip of width kSlowWidth in lap fraction), and the radius dips with width kDipWidth.
constexpr double kSlowDepth = 0.75, kSlowWidth = 0.06, kDipWidth = 0.045;

double Unit(std::mt19937_64& engine) { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }

double SmootherStep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (s * (6 * s - 15) + 10);
}

double Gaussian(double x, double sigma) { return std::exp(-0.5 * (x / sigma) * (x / sigma)); }

// Signed difference a − b wrapped into (−π, π].
double AngleDiff(double a, double b) { return std::remainder(a - b, kTwoPi); }

// ∫₀^τ Gaussian(s − μ, σ) ds.
double GaussianIntegral(double tau, double mu, double sigma) {
  const double k = sigma * std::sqrt(M_PI / 2);
  return k * (std::erf((tau - mu) / (sigma * std::sqrt(2.0))) - std::erf(-mu / (sigma * std::sqrt(2.0))));
}

}  // namespace

calib::Pose HandHeldCameraPose(const Eigen::Vector3d& centre, double yaw, double pitch, double roll) {
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r_wc;
  r_wc << right, down, forward;  // columns: the camera's x, y, z axes in the world
  r_wc = r_wc * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), centre);
}

OrbitWalk::OrbitWalk(double duration, uint64_t seed, const OrbitWalkOptions& options) : duration_(duration), options_(options) {
  std::mt19937_64 engine(seed);
  pan_phase_ = kTwoPi * Unit(engine);
  pitch_phase_ = kTwoPi * Unit(engine);
  roll_phase_ = kTwoPi * Unit(engine);
  bob_phase_ = kTwoPi * Unit(engine);
  glance_sign_ = Unit(engine) < 0.5 ? -1.0 : 1.0;
  for (double& phase : shake_phase_) phase = kTwoPi * Unit(engine);
}

double OrbitWalk::RingRadius(double azimuth) const {
  // Measured in the room for the default subject (-0.2, 0.25): every direction has at least
  // 1.66 m of free floor before a wall (0.45 m margin) or a box (0.35 m margin); toward −x and
  // toward +x-slightly-south the room opens to 2.4 m and more, where the ring widens.
  return 1.6 + 0.9 * Gaussian(AngleDiff(azimuth, 175 * kDeg), 15 * kDeg) +
         1.0 * Gaussian(AngleDiff(azimuth, 345 * kDeg), 12 * kDeg);
}

double OrbitWalk::LapTwoAzimuth(double fraction) const {
  const double mu = options_.close_fraction;
  const double slowed = fraction - kSlowDepth * GaussianIntegral(fraction, mu, kSlowWidth);
  const double whole = 1 - kSlowDepth * GaussianIntegral(1, mu, kSlowWidth);
  return options_.start_azimuth_deg * kDeg + kTwoPi + kTwoPi * slowed / whole;
}

double OrbitWalk::CloseApproachAzimuth() const { return std::remainder(LapTwoAzimuth(options_.close_fraction), kTwoPi); }

calib::Pose OrbitWalk::At(double t) const {
  const double half = duration_ / 2;
  const bool second = t >= half;
  const double fraction = std::clamp(second ? (t - half) / half : t / half, 0.0, 1.0);
  auto shake = [&](int i, double amplitude) {
    return amplitude * (std::sin(kTwoPi * 6.1 * t + shake_phase_[i]) + 0.6 * std::sin(kTwoPi * 9.7 * t + shake_phase_[5 - i]));
  };

  // Where the walker is.
  const double azimuth = second ? LapTwoAzimuth(fraction) : options_.start_azimuth_deg * kDeg + kTwoPi * fraction;
  const double close = second ? Gaussian(fraction - options_.close_fraction, kDipWidth) : 0.0;
  const double radius = RingRadius(azimuth) * (1 - close) + options_.close_distance * close;
  const Eigen::Vector3d subject = Subject();
  Eigen::Vector3d centre = subject + radius * Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0);
  centre.z() = 1.55 + 0.03 * std::sin(kTwoPi * t / 7.3 + bob_phase_) + 0.015 * std::sin(kTwoPi * 1.7 * t + bob_phase_);
  centre += Eigen::Vector3d(shake(3, 0.0015), shake(4, 0.0015), shake(5, 0.0015));

  // Where it looks: at the character's chest (its head when close), off by the hand-held
  // wobble; lap 1 pans widely across the room instead, and lap 2 glances away once.
  const Eigen::Vector3d target = subject + Eigen::Vector3d(0, 0, 1.1 + 0.25 * close);
  double yaw_offset, pitch_offset;
  if (!second) {
    const double window = SmootherStep(fraction / 0.06) * SmootherStep((1 - fraction) / 0.06);
    yaw_offset = window * 40 * kDeg * std::sin(kTwoPi * t / 5.5 + pan_phase_);
    pitch_offset = window * 6 * kDeg * std::sin(kTwoPi * t / 4.3 + pitch_phase_);
  } else {
    const double since = t - (half + options_.glance_fraction * half);
    const double glance = since < 0.85 ? SmootherStep(since / 0.35) : 1 - SmootherStep((since - 0.85) / 0.45);
    yaw_offset = 3 * kDeg * std::sin(kTwoPi * t / 3.1 + pan_phase_) + glance_sign_ * 50 * kDeg * glance;
    pitch_offset = 2 * kDeg * std::sin(kTwoPi * t / 4.3 + pitch_phase_);
  }
  const Eigen::Vector3d look = target - centre;
  const double yaw = std::atan2(look.y(), look.x()) + yaw_offset + shake(0, 0.002);
  const double pitch = std::atan2(look.z(), look.head<2>().norm()) + pitch_offset + shake(1, 0.002);
  const double roll = 0.03 * std::sin(kTwoPi * t / 4.1 + roll_phase_) + shake(2, 0.0015);

  return HandHeldCameraPose(centre, yaw, pitch, roll);
}

}  // namespace arview::synth
