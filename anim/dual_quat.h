#pragma once
// Unit dual quaternions for rigid transforms (docs/method.md §1, Eq. 1), header-only, for float and
// double: q̂ = r + ε d with r the rotation and d = ½ (0, t) r.
//
//   DualQuatd q = DualQuatd::FromRotationTranslation(R, t);
//   Eigen::Vector3d p2 = q.TransformPoint(p);       // = R p + t
//   Eigen::Matrix4d M = q.ToMatrix();
//   DualQuatd c = a * b;                            // apply b, then a (as for matrices)
//   DualLog<double> l = q.Log();  q == DualQuatd::Exp(l)
//   DualQuatd s = ScLerp(a, b, 0.3);                // screw-linear interpolation
//
// q and −q are the same rigid transform. Functions here that combine several dual quaternions
// (ScLerp, and Dlb/Dib in blend.h) align their signs first.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace arview::anim {

// The logarithm of a unit dual quaternion: a "dual vector" (half screw angle times the screw
// axis), real part and dual part, each a 3-vector. Exp() inverts Log().
template <class T>
struct DualLog {
  Eigen::Matrix<T, 3, 1> real = Eigen::Matrix<T, 3, 1>::Zero();
  Eigen::Matrix<T, 3, 1> dual = Eigen::Matrix<T, 3, 1>::Zero();

  DualLog& operator+=(const DualLog& o) { real += o.real; dual += o.dual; return *this; }
  DualLog operator*(T s) const { return {real * s, dual * s}; }
  // Euclidean norm of the 6-vector (the stopping test of DIB, Algorithm 1).
  T Norm() const { return std::sqrt(real.squaredNorm() + dual.squaredNorm()); }
};

template <class T>
class DualQuat {
 public:
  using Scalar = T;
  using Quat = Eigen::Quaternion<T>;
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  using Vec4 = Eigen::Matrix<T, 4, 1>;
  using Mat4 = Eigen::Matrix<T, 4, 4>;

  DualQuat() : real_(T(1), T(0), T(0), T(0)), dual_(T(0), T(0), T(0), T(0)) {}
  DualQuat(const Quat& real, const Quat& dual) : real_(real), dual_(dual) {}

  static DualQuat Identity() { return DualQuat(); }

  // Eq. 1: rotation `r` (normalised here), then translation `t`.
  static DualQuat FromRotationTranslation(const Quat& r, const Vec3& t) {
    const Quat rn = r.normalized();
    const Quat tq(T(0), t.x() * T(0.5), t.y() * T(0.5), t.z() * T(0.5));
    return DualQuat(rn, tq * rn);
  }
  static DualQuat FromTranslation(const Vec3& t) { return FromRotationTranslation(Quat::Identity(), t); }

  // The rigid part of an affine matrix: its rotation is orthonormalised (any scale is dropped).
  static DualQuat FromMatrix(const Mat4& m) {
    Eigen::Matrix<T, 3, 3> a = m.template block<3, 3>(0, 0);
    Eigen::JacobiSVD<Eigen::Matrix<T, 3, 3>> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix<T, 3, 3> r = svd.matrixU() * svd.matrixV().transpose();
    if (r.determinant() < T(0)) {
      Eigen::Matrix<T, 3, 3> u = svd.matrixU();
      u.col(2) = -u.col(2);
      r = u * svd.matrixV().transpose();
    }
    return FromRotationTranslation(Quat(r), m.template block<3, 1>(0, 3));
  }

  const Quat& real() const { return real_; }
  const Quat& dual() const { return dual_; }
  Quat& real() { return real_; }
  Quat& dual() { return dual_; }

  Quat Rotation() const { return real_; }
  Vec3 Translation() const {
    const Quat t = dual_ * real_.conjugate();
    return T(2) * t.vec();
  }

  Mat4 ToMatrix() const {
    Mat4 m = Mat4::Identity();
    m.template block<3, 3>(0, 0) = real_.toRotationMatrix();
    m.template block<3, 1>(0, 3) = Translation();
    return m;
  }

  Vec3 TransformPoint(const Vec3& p) const { return real_ * p + Translation(); }
  Vec3 TransformVector(const Vec3& v) const { return real_ * v; }

  DualQuat operator*(const DualQuat& o) const {
    Quat d1 = real_ * o.dual_;
    Quat d2 = dual_ * o.real_;
    return DualQuat(real_ * o.real_, Quat(d1.coeffs() + d2.coeffs()));
  }
  DualQuat operator+(const DualQuat& o) const {
    return DualQuat(Quat(real_.coeffs() + o.real_.coeffs()), Quat(dual_.coeffs() + o.dual_.coeffs()));
  }
  DualQuat operator*(T s) const { return DualQuat(Quat(real_.coeffs() * s), Quat(dual_.coeffs() * s)); }
  DualQuat operator-() const { return DualQuat(Quat(-real_.coeffs()), Quat(-dual_.coeffs())); }

  // Quaternion conjugate of both parts: the inverse of a unit dual quaternion.
  DualQuat Conjugate() const { return DualQuat(real_.conjugate(), dual_.conjugate()); }
  // Dual-number conjugate: r − ε d.
  DualQuat DualConjugate() const { return DualQuat(real_, Quat(-dual_.coeffs())); }
  // Both conjugates at once: r* − ε d*.
  DualQuat CombinedConjugate() const {
    return DualQuat(real_.conjugate(), Quat(-dual_.conjugate().coeffs()));
  }

  // 4D dot product of the real parts: its sign tells whether two dual quaternions are on the
  // same side of the double cover.
  T RealDot(const DualQuat& o) const { return real_.coeffs().dot(o.real_.coeffs()); }

  // Projects onto the unit manifold: real part of norm 1 and real·dual = 0.
  // A zero real part has no projection: returns identity (callers check RealNorm first).
  DualQuat Normalized() const {
    const T n = real_.norm();
    if (!(n > T(0))) return DualQuat();
    const Vec4 r = real_.coeffs() / n;
    Vec4 d = dual_.coeffs() / n;
    d -= r * r.dot(d);
    return DualQuat(Quat(r), Quat(d));
  }
  T RealNorm() const { return real_.norm(); }

  bool IsUnit(T tol) const {
    return std::abs(real_.norm() - T(1)) <= tol && std::abs(real_.coeffs().dot(dual_.coeffs())) <= tol;
  }

  // Screw logarithm of a unit dual quaternion: half the dual angle times the dual axis.
  // Chooses the representative with non-negative real scalar part, i.e. the short way round.
  DualLog<T> Log() const {
    Vec4 rc = real_.coeffs(), dc = dual_.coeffs();
    if (rc.w() < T(0)) { rc = -rc; dc = -dc; }
    const Vec3 rv = rc.template head<3>();
    const Vec3 dv = dc.template head<3>();
    const T c = rc.w(), dw = dc.w();
    const T s = rv.norm();
    const T a = std::atan2(s, c);
    T k, g;  // k = a/s, g = (s − a c)/s³, both with series near a = 0
    if (s < SmallAngle()) {
      k = T(1) + a * a / T(6);
      g = T(1) / T(3) + a * a * T(2) / T(15);
    } else {
      k = a / s;
      g = (s - a * c) / (s * s * s);
    }
    DualLog<T> l;
    l.real = k * rv;
    l.dual = k * dv - dw * g * rv;
    return l;
  }

  static DualQuat Exp(const DualLog<T>& l) {
    const Vec3& u = l.real;
    const Vec3& w = l.dual;
    const T a = u.norm();
    const T s = std::sin(a), c = std::cos(a);
    T sa, h;  // sa = sin(a)/a, h = (c − sin(a)/a)/a²
    if (a < SmallAngle()) {
      sa = T(1) - a * a / T(6);
      h = T(-1) / T(3) + a * a / T(30);
    } else {
      sa = s / a;
      h = (c - sa) / (a * a);
    }
    const T uw = u.dot(w);
    Quat r;
    r.w() = c;
    r.vec() = sa * u;
    Quat d;
    d.w() = -uw * sa;
    d.vec() = sa * w + uw * h * u;
    return DualQuat(r, d);
  }

  template <class U>
  DualQuat<U> cast() const {
    return DualQuat<U>(real_.template cast<U>(), dual_.template cast<U>());
  }

 private:
  static constexpr T SmallAngle() { return sizeof(T) >= 8 ? T(1e-4) : T(3e-3); }
  Quat real_;
  Quat dual_;
};

using DualQuatd = DualQuat<double>;
using DualQuatf = DualQuat<float>;

// Returns q or −q, whichever has a non-negative real-part dot product with `reference`.
template <class T>
DualQuat<T> AlignedWith(const DualQuat<T>& q, const DualQuat<T>& reference) {
  return q.RealDot(reference) < T(0) ? -q : q;
}

// Screw-linear interpolation (constant speed along the screw motion from a to b), short way.
template <class T>
DualQuat<T> ScLerp(const DualQuat<T>& a, const DualQuat<T>& b, T t) {
  const DualQuat<T> delta = a.Conjugate() * AlignedWith(b, a);
  return (a * DualQuat<T>::Exp(delta.Log() * t)).Normalized();
}

}  // namespace arview::anim
