#include "room/sh.h"

#include <Eigen/Dense>

#include <cmath>

namespace arview::room {
namespace {

constexpr double kY0 = 0.282094791773878;  // 1 / (2√π)
constexpr double kY1 = 0.488602511902920;  // √(3 / 4π)
constexpr double kY2a = 1.092548430592079;  // √(15 / 4π)
constexpr double kY2b = 0.315391565252520;  // √(5 / 16π)
constexpr double kY2c = 0.546274215296040;  // √(15 / 16π)

// Band of coefficient i.
int Band(int i) { return i == 0 ? 0 : (i < 4 ? 1 : 2); }

Eigen::Matrix3d BandTwoMatrix(const double* c) {
  Eigen::Matrix3d q;
  q(0, 0) = -kY2b * c[2] + kY2c * c[4];
  q(1, 1) = -kY2b * c[2] - kY2c * c[4];
  q(2, 2) = 2 * kY2b * c[2];
  q(0, 1) = q(1, 0) = kY2a * c[0] / 2;
  q(1, 2) = q(2, 1) = kY2a * c[1] / 2;
  q(0, 2) = q(2, 0) = kY2a * c[3] / 2;
  return q;
}

}  // namespace

Sh9 ShBasis(const Eigen::Vector3d& d) {
  const double x = d.x(), y = d.y(), z = d.z();
  return {kY0,
          kY1 * y,
          kY1 * z,
          kY1 * x,
          kY2a * x * y,
          kY2a * y * z,
          kY2b * (3 * z * z - 1),
          kY2a * x * z,
          kY2c * (x * x - y * y)};
}

ShRgb ProjectRadiance(const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& radiance, int samples) {
  ShRgb sh;
  sh.fill(Eigen::Vector3d::Zero());
  const double golden = M_PI * (3 - std::sqrt(5.0));
  const double weight = 4 * M_PI / samples;
  for (int i = 0; i < samples; ++i) {
    const double z = 1 - (2 * i + 1.0) / samples;
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Eigen::Vector3d d(r * std::cos(golden * i), r * std::sin(golden * i), z);
    const Eigen::Vector3d value = radiance(d) * weight;
    const Sh9 y = ShBasis(d);
    for (int k = 0; k < 9; ++k) sh[k] += value * y[k];
  }
  return sh;
}

ShRgb CapSh(const Eigen::Vector3d& axis, double half_angle, const Eigen::Vector3d& radiance) {
  const double c = std::cos(half_angle);
  const double zonal[3] = {2 * M_PI * (1 - c), M_PI * (1 - c * c), M_PI * (c - c * c * c)};
  const Sh9 y = ShBasis(axis.normalized());
  ShRgb sh;
  for (int k = 0; k < 9; ++k) sh[k] = radiance * (zonal[Band(k)] * y[k]);
  return sh;
}

ShRgb ConstantSh(const Eigen::Vector3d& radiance) {
  ShRgb sh;
  sh.fill(Eigen::Vector3d::Zero());
  sh[0] = radiance * (4 * M_PI * kY0);
  return sh;
}

ShRgb operator+(const ShRgb& a, const ShRgb& b) {
  ShRgb sum;
  for (int k = 0; k < 9; ++k) sum[k] = a[k] + b[k];
  return sum;
}

ShRgb Scaled(const ShRgb& sh, const Eigen::Vector3d& gain) {
  ShRgb out;
  for (int k = 0; k < 9; ++k) out[k] = sh[k].cwiseProduct(gain);
  return out;
}

Eigen::Vector3d EvaluateSh(const ShRgb& sh, const Eigen::Vector3d& d) {
  const Sh9 y = ShBasis(d);
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  for (int k = 0; k < 9; ++k) value += sh[k] * y[k];
  return value;
}

Eigen::Vector3d IrradianceSh(const ShRgb& sh, const Eigen::Vector3d& n) {
  const double band[3] = {M_PI, 2 * M_PI / 3, M_PI / 4};
  const Sh9 y = ShBasis(n);
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  for (int k = 0; k < 9; ++k) e += sh[k] * (band[Band(k)] * y[k]);
  return e;
}

DominantLight ExtractDominantLight(const ShRgb& sh) {
  DominantLight light;
  const Eigen::Vector3d w = LuminanceWeights();
  const Eigen::Vector3d linear(sh[3].dot(w), sh[1].dot(w), sh[2].dot(w));  // (x, y, z)
  if (linear.norm() < 1e-12) {
    light.ambient = (sh[0] / (4 * M_PI * kY0)).cwiseMax(0.0);
    return light;
  }
  light.direction = linear.normalized();
  const Sh9 y = ShBasis(light.direction);
  // Band 1 only: Σ_m Y_1m(d)² = 3 / 4π. Band 2 is left out because a room is not one light: lit
  // all round its horizon (walls, windows), its band 2 is negative along its brightest
  // direction, and a fit over bands 1 and 2 then came out black (arview demo's rendered room:
  // colour (0, 0, 0), so no cast shadow). Both fits are exact for one directional light.
  Eigen::Vector3d projected = Eigen::Vector3d::Zero();
  for (int k = 1; k < 4; ++k) projected += sh[k] * y[k];
  light.color = (projected / (3 / (4 * M_PI))).cwiseMax(0.0);
  light.ambient = ((sh[0] - light.color * kY0) / (4 * M_PI * kY0)).cwiseMax(0.0);
  return light;
}

Sh9 RotateSh(const Sh9& c, const Eigen::Matrix3d& r) {
  Sh9 out;
  out[0] = c[0];
  const Eigen::Vector3d v = r * Eigen::Vector3d(c[3], c[1], c[2]);
  out[3] = v.x(), out[1] = v.y(), out[2] = v.z();
  const Eigen::Matrix3d q = r * BandTwoMatrix(&c[4]) * r.transpose();
  out[4] = 2 * q(0, 1) / kY2a;
  out[5] = 2 * q(1, 2) / kY2a;
  out[6] = q(2, 2) / (2 * kY2b);
  out[7] = 2 * q(0, 2) / kY2a;
  out[8] = (q(0, 0) - q(1, 1)) / (2 * kY2c);
  return out;
}

ShRgb RotateSh(const ShRgb& c, const Eigen::Matrix3d& r) {
  ShRgb out;
  for (int channel = 0; channel < 3; ++channel) {
    Sh9 one;
    for (int k = 0; k < 9; ++k) one[k] = c[k][channel];
    const Sh9 rotated = RotateSh(one, r);
    for (int k = 0; k < 9; ++k) out[k][channel] = rotated[k];
  }
  return out;
}

Eigen::Vector3d DotSh(const ShRgb& light, const Sh9& transfer) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int k = 0; k < 9; ++k) sum += light[k] * transfer[k];
  return sum;
}

}  // namespace arview::room
