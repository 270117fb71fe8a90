#pragma once
// Weights of the key viewpoints for the current viewpoint (docs/method.md §1, Eq. 2), and a
// local-support alternative.
//
//   ViewSphere sphere(key_directions, {WeightingMode::kInverseDistance, DistanceKind::kGeodesic, 3.0});
//   std::vector<double> w(sphere.size());
//   sphere.Weights(viewpoint, w);         // convex: w ≥ 0, Σ w = 1; no allocation
//
// kInverseDistance (Eq. 2): w^k ∝ D(v, v^k)^(−α). A viewpoint on a key (D below 1e-12) gives
// that key weight 1, split evenly among keys at the same direction.
// kLocalSupport: only the nearest keys contribute.
//   - Keys that span the sphere (their convex hull holds the centre): the hull is a spherical
//     triangulation; the viewpoint's ray meets one triangle and the weights are the barycentric
//     coordinates of that point (gnomonic projection), so at most 3 keys are non-zero.
//   - Keys on one great circle (a ring, e.g. all on the horizon): linear in angle between the two
//     ring neighbours of the viewpoint's projection; towards the ring's poles, and inside a gap
//     of the ring wider than 180° (a partial ring), it fades smoothly into Eq. 2.
//   - Any other layout (keys spread over a cap, neither spanning nor a ring): Eq. 2.
// Both modes are continuous in the viewpoint.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <span>
#include <vector>

namespace arview::anim {

enum class DistanceKind { kGeodesic, kChordal };
enum class WeightingMode { kInverseDistance, kLocalSupport };

struct ViewSphereOptions {
  WeightingMode mode = WeightingMode::kInverseDistance;
  DistanceKind distance = DistanceKind::kGeodesic;
  double alpha = 3.0;
};

// A direction as a user gives it (a scene's key viewpoint, `--viewpoint`, a character's
// forward): any vector whose length, measured without overflow, lies within
// [kMinDirectionLength, kMaxDirectionLength]. Beyond them its norm overflows or its components
// are denormal: (1e300, 1e300, 1e300) normalised to (0, 0, 0) and was reported as "zero length".
inline constexpr double kMinDirectionLength = 1e-9;
inline constexpr double kMaxDirectionLength = 1e12;

// The unit vector of `v`; throws Error saying why there is none: "(1e+300, 0, 0) is 1e+300
// long, beyond 1e+12 ...", "... is 4.94e-324 long, below 1e-09: too short to give a direction",
// "... is not finite". The caller puts the what and where before it.
Eigen::Vector3d UnitDirection(const Eigen::Vector3d& v);

class ViewSphere {
 public:
  // `keys` are normalised here; throws Error if one has (near) zero length, if there are none,
  // or if alpha is not positive.
  ViewSphere(std::vector<Eigen::Vector3d> keys, const ViewSphereOptions& options = {});

  int size() const { return static_cast<int>(keys_.size()); }
  const std::vector<Eigen::Vector3d>& keys() const { return keys_; }
  const ViewSphereOptions& options() const { return options_; }

  // `viewpoint` need not be unit; a zero vector gives equal weights. `out` has size() entries.
  void Weights(const Eigen::Vector3d& viewpoint, std::span<double> out) const;

  // What kLocalSupport found in the key layout (for tests and `anim weights`). Triangles and
  // ring indices refer to distinct directions (directions()), not to keys.
  enum class Layout { kSpanning, kRing, kOther };
  Layout layout() const { return layout_; }
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  const std::vector<Eigen::Vector3d>& directions() const { return dirs_; }

 private:
  static constexpr int kMaxStackDirs = 64;  // more distinct keys than this allocate per call
  void BuildHull();
  void DetectRing();
  // These work on distinct directions (dirs_), not on keys.
  void InverseDistance(const Eigen::Vector3d& v, std::span<double> out) const;
  void Triangulated(const Eigen::Vector3d& v, std::span<double> out) const;
  void Ring(const Eigen::Vector3d& v, std::span<double> out) const;

  std::vector<Eigen::Vector3d> keys_;
  std::vector<Eigen::Vector3d> dirs_;           // distinct key directions
  std::vector<std::vector<int>> members_;       // keys at each direction
  ViewSphereOptions options_;
  Layout layout_ = Layout::kOther;
  std::vector<std::array<int, 3>> triangles_;
  // Ring layout: unit normal, an in-plane basis, and key indices sorted by angle.
  Eigen::Vector3d ring_normal_ = Eigen::Vector3d::UnitY();
  Eigen::Vector3d ring_x_ = Eigen::Vector3d::UnitX(), ring_y_ = Eigen::Vector3d::UnitZ();
  std::vector<int> ring_order_;
  std::vector<double> ring_angle_;  // angle of ring_order_[i], increasing, in [0, 2π)
};

// A unit direction from azimuth and elevation in degrees, in a frame given by the character's
// forward and up axes: azimuth 0 is forward, +90 is towards up × forward (the character's left
// for a right-handed frame), elevation +90 is up.
Eigen::Vector3d DirectionFromAzimuthElevation(double azimuth_deg, double elevation_deg,
                                              const Eigen::Vector3d& forward = Eigen::Vector3d::UnitZ(),
                                              const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

}  // namespace arview::anim
