#include "anim/view_sphere.h"

#include "anim/character.h"  // Error

#include <algorithm>
#include <cmath>
#include <map>
#include <iomanip>
#include <numeric>
#include <sstream>

namespace arview::anim {
namespace {

constexpr double kExactHit = 1e-12;    // distance under which the viewpoint sits on a key
constexpr double kPlaneTol = 1e-9;     // coplanarity for the hull and the ring
constexpr double kPoleStart = M_PI / 3;  // ring mode fades into Eq. 2 from this elevation on
constexpr double kGapMargin = M_PI / 6;  // and over this azimuth inside a partial ring's gap

double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

double Wrap2Pi(double a) {
  a = std::fmod(a, 2 * M_PI);
  return a < 0 ? a + 2 * M_PI : a;
}

}  // namespace

Eigen::Vector3d UnitDirection(const Eigen::Vector3d& v) {
  auto say = [&](const std::string& problem) {
    std::ostringstream s;
    s << std::setprecision(6) << '(' << v.x() << ", " << v.y() << ", " << v.z() << ") " << problem;
    return Error(s.str());
  };
  if (!v.allFinite()) throw say("is not finite");
  // Scaled by its largest component first: the norm of (1e300, 1e300, 1e300) overflows.
  const double largest = v.cwiseAbs().maxCoeff();
  const double length = largest > 0 ? largest * (v / largest).norm() : 0.0;
  std::ostringstream figure;
  figure << std::setprecision(3) << length;
  if (length > kMaxDirectionLength) {
    std::ostringstream limit;
    limit << kMaxDirectionLength;
    throw say("is " + figure.str() + " long, beyond " + limit.str() + " (a direction such as [0, 0, 1] is expected)");
  }
  if (!(length >= kMinDirectionLength)) {
    std::ostringstream limit;
    limit << kMinDirectionLength;
    throw say("is " + figure.str() + " long, below " + limit.str() + ": too short to give a direction");
  }
  return v / length;
}

ViewSphere::ViewSphere(std::vector<Eigen::Vector3d> keys, const ViewSphereOptions& options)
    : keys_(std::move(keys)), options_(options) {
  if (keys_.empty()) throw Error("view sphere: no key viewpoints");
  if (!(options_.alpha > 0) || !std::isfinite(options_.alpha))
    throw Error("view sphere: alpha must be positive, got " + std::to_string(options_.alpha));
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    try {
      keys_[k] = UnitDirection(keys_[k]);
    } catch (const Error& e) {
      throw Error("view sphere: key viewpoint " + std::to_string(k) + " " + e.what());
    }
  }
  // Distinct directions; keys sharing one split its weight.
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    int found = -1;
    for (std::size_t u = 0; u < dirs_.size(); ++u)
      if ((dirs_[u] - keys_[k]).norm() < 1e-9) found = static_cast<int>(u);
    if (found < 0) {
      dirs_.push_back(keys_[k]);
      members_.emplace_back();
      found = static_cast<int>(dirs_.size()) - 1;
    }
    members_[found].push_back(static_cast<int>(k));
  }
  if (dirs_.size() == 1) {
    layout_ = Layout::kOther;
    return;
  }
  BuildHull();
  if (layout_ != Layout::kSpanning) DetectRing();
}

void ViewSphere::BuildHull() {
  const int n = static_cast<int>(dirs_.size());
  std::map<std::vector<int>, Eigen::Vector3d> faces;  // coplanar vertex set → outward normal
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        Eigen::Vector3d nn = (dirs_[j] - dirs_[i]).cross(dirs_[k] - dirs_[i]);
        if (nn.norm() < 1e-9) continue;
        nn.normalize();
        bool above = false, below = false;
        std::vector<int> on;
        for (int m = 0; m < n; ++m) {
          const double d = nn.dot(dirs_[m] - dirs_[i]);
          if (d > kPlaneTol) above = true;
          else if (d < -kPlaneTol) below = true;
          else on.push_back(m);
        }
        if (above && below) continue;
        if (!above && !below) return;  // every key on one plane: no solid hull
        faces.emplace(on, above ? Eigen::Vector3d(-nn) : nn);
      }
  if (faces.size() < 4) return;
  // The centre must lie strictly inside every face.
  for (const auto& [verts, normal] : faces)
    if (normal.dot(dirs_[verts[0]]) < 1e-6) return;
  for (const auto& [verts, normal] : faces) {
    // Order the face's vertices counter-clockwise around its normal, then fan.
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int v : verts) centre += dirs_[v];
    centre /= double(verts.size());
    const Eigen::Vector3d ax = (dirs_[verts[0]] - centre).normalized();
    const Eigen::Vector3d ay = normal.cross(ax);
    std::vector<std::pair<double, int>> ordered;
    for (int v : verts) {
      const Eigen::Vector3d d = dirs_[v] - centre;
      ordered.emplace_back(std::atan2(d.dot(ay), d.dot(ax)), v);
    }
    std::sort(ordered.begin(), ordered.end());
    for (std::size_t t = 1; t + 1 < ordered.size(); ++t)
      triangles_.push_back({ordered[0].second, ordered[t].second, ordered[t + 1].second});
  }
  layout_ = Layout::kSpanning;
}

void ViewSphere::DetectRing() {
  const int n = static_cast<int>(dirs_.size());
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = 1; i < n && normal.isZero(); ++i) {
    const Eigen::Vector3d c = dirs_[0].cross(dirs_[i]);
    if (c.norm() > 1e-6) normal = c.normalized();
  }
  if (normal.isZero()) {  // two antipodal directions: any great circle through them
    normal = dirs_[0].unitOrthogonal();
  }
  for (int i = 0; i < n; ++i)
    if (std::abs(normal.dot(dirs_[i])) > 1e-6) return;  // not one great circle
  layout_ = Layout::kRing;
  ring_normal_ = normal;
  ring_x_ = dirs_[0];
  ring_y_ = normal.cross(ring_x_);
  std::vector<std::pair<double, int>> ordered;
  for (int i = 0; i < n; ++i)
    ordered.emplace_back(Wrap2Pi(std::atan2(dirs_[i].dot(ring_y_), dirs_[i].dot(ring_x_))), i);
  std::sort(ordered.begin(), ordered.end());
  for (const auto& [a, i] : ordered) {
    ring_angle_.push_back(a);
    ring_order_.push_back(i);
  }
}

void ViewSphere::Weights(const Eigen::Vector3d& viewpoint, std::span<double> out) const {
  if (out.size() != keys_.size())
    throw Error("view sphere: " + std::to_string(out.size()) + " weight slots for " + std::to_string(keys_.size()) + " keys");
  const int nd = static_cast<int>(dirs_.size());
  // Work on distinct directions in a fixed-size scratch when possible.
  double scratch[kMaxStackDirs];
  std::vector<double> heap;
  double* w = scratch;
  if (nd > kMaxStackDirs) {
    heap.resize(nd);
    w = heap.data();
  }
  const std::span<double> wd(w, nd);
  const double len = viewpoint.norm();
  if (!(len > 0) || !std::isfinite(len)) {
    std::fill(wd.begin(), wd.end(), 1.0 / nd);
  } else {
    const Eigen::Vector3d v = viewpoint / len;
    if (options_.mode == WeightingMode::kInverseDistance || nd == 1 || layout_ == Layout::kOther) InverseDistance(v, wd);
    else if (layout_ == Layout::kSpanning) Triangulated(v, wd);
    else Ring(v, wd);
  }
  std::fill(out.begin(), out.end(), 0.0);
  for (int u = 0; u < nd; ++u)
    for (int k : members_[u]) out[k] = w[u] / double(members_[u].size());
}

void ViewSphere::InverseDistance(const Eigen::Vector3d& v, std::span<double> w) const {
  const int nd = static_cast<int>(dirs_.size());
  int hits = 0;
  for (int u = 0; u < nd; ++u) {
    const double d = options_.distance == DistanceKind::kGeodesic
                         ? std::atan2(v.cross(dirs_[u]).norm(), v.dot(dirs_[u]))
                         : (v - dirs_[u]).norm();
    if (d < kExactHit) {
      w[u] = -1;  // marks an exact hit
      ++hits;
    } else {
      w[u] = std::pow(d, -options_.alpha);
    }
  }
  if (hits > 0) {
    for (int u = 0; u < nd; ++u) w[u] = w[u] < 0 ? 1.0 / hits : 0.0;
    return;
  }
  const double sum = std::accumulate(w.begin(), w.end(), 0.0);
  for (double& x : w) x /= sum;
}

void ViewSphere::Triangulated(const Eigen::Vector3d& v, std::span<double> w) const {
  std::fill(w.begin(), w.end(), 0.0);
  double best_min = -1e300;
  std::array<double, 3> best_b{1, 0, 0};
  const std::array<int, 3>* best = &triangles_.front();
  for (const auto& tri : triangles_) {
    const Eigen::Vector3d& a = dirs_[tri[0]];
    const Eigen::Vector3d& b = dirs_[tri[1]];
    const Eigen::Vector3d& c = dirs_[tri[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double nv = n.dot(v);
    if (nv <= 1e-9 * n.norm()) continue;  // faces away, or the ray runs along its plane
    const Eigen::Vector3d p = v * (n.dot(a) / nv);  // the ray meets the triangle's plane here
    const double area = n.squaredNorm();
    const std::array<double, 3> bc{(b - p).cross(c - p).dot(n) / area, (c - p).cross(a - p).dot(n) / area,
                                   (a - p).cross(b - p).dot(n) / area};
    const double m = std::min({bc[0], bc[1], bc[2]});
    if (m > best_min) {
      best_min = m;
      best_b = bc;
      best = &tri;
    }
    if (m >= 0) break;
  }
  double sum = 0;
  for (int i = 0; i < 3; ++i) sum += (best_b[i] = std::max(best_b[i], 0.0));
  for (int i = 0; i < 3; ++i) w[(*best)[i]] = best_b[i] / sum;
}

void ViewSphere::Ring(const Eigen::Vector3d& v, std::span<double> w) const {
  const int n = static_cast<int>(ring_order_.size());
  const double up = v.dot(ring_normal_);
  const Eigen::Vector3d p = v - up * ring_normal_;
  const double elevation = std::atan2(std::abs(up), p.norm());
  const double s_pole = SmoothStep(kPoleStart, M_PI / 2, elevation);
  std::fill(w.begin(), w.end(), 0.0);
  if (s_pole < 1) {
    const double phi = Wrap2Pi(std::atan2(p.dot(ring_y_), p.dot(ring_x_)));
    // Neighbours: the last key at or before phi (cyclically) and the next one.
    int i = n - 1;
    for (int t = 0; t < n; ++t)
      if (ring_angle_[t] <= phi) i = t;
    const int j = (i + 1) % n;
    const double gap = Wrap2Pi(ring_angle_[j] - ring_angle_[i]);
    const double from_i = Wrap2Pi(phi - ring_angle_[i]);
    double largest = 0;
    for (int t = 0; t < n; ++t) largest = std::max(largest, Wrap2Pi(ring_angle_[(t + 1) % n] - ring_angle_[t]));
    const bool in_open_gap = gap >= M_PI - 1e-9 && gap >= largest - 1e-12;
    double s_gap = 0;
    if (in_open_gap) {
      // Outside the ring's span: the nearer end key, fading into Eq. 2 away from it.
      const double to_j = gap - from_i;
      const bool near_i = from_i <= to_j;
      w[ring_order_[near_i ? i : j]] = 1.0;
      s_gap = SmoothStep(0, kGapMargin, std::min(from_i, to_j));
    } else {
      const double f = gap > 0 ? from_i / gap : 0.0;
      w[ring_order_[i]] += 1 - f;
      w[ring_order_[j]] += f;
    }
    const double local = (1 - s_pole) * (1 - s_gap);
    if (local < 1) {
      double eq2[kMaxStackDirs];
      std::vector<double> heap;
      double* e = eq2;
      if (n > kMaxStackDirs) {
        heap.resize(n);
        e = heap.data();
      }
      InverseDistance(v, std::span<double>(e, n));
      for (int u = 0; u < n; ++u) w[u] = local * w[u] + (1 - local) * e[u];
    }
  } else {
    InverseDistance(v, w);
  }
}

Eigen::Vector3d DirectionFromAzimuthElevation(double azimuth_deg, double elevation_deg, const Eigen::Vector3d& forward,
                                              const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d f = (forward - forward.dot(u) * u).normalized();
  const Eigen::Vector3d l = u.cross(f);
  const double az = azimuth_deg * M_PI / 180, el = elevation_deg * M_PI / 180;
  return (std::cos(el) * (std::cos(az) * f + std::sin(az) * l) + std::sin(el) * u).normalized();
}

}  // namespace arview::anim
