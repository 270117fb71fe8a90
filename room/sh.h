#pragma once
// Order-2 real spherical harmonics (9 coefficients), the basis the mixed-reality seed paper
// lights its characters in (docs/method.md §4): projection of a radiance function, the diffuse
// irradiance closed form (Ramamoorthi and Hanrahan 2001), a dominant directional light taken
// out of the coefficients, and rotation (for the per-vertex transfer of dynamic PRT).
//
// Index order (Sloan's "Stupid SH tricks" convention), for a unit direction (x, y, z):
//   0: Y00 = 0.282095                  1: Y1-1 = 0.488603 y   2: Y10 = 0.488603 z
//   3: Y11 = 0.488603 x                4: Y2-2 = 1.092548 xy  5: Y2-1 = 1.092548 yz
//   6: Y20 = 0.315392 (3z² − 1)        7: Y21 = 1.092548 xz   8: Y22 = 0.546274 (x² − y²)

#include <Eigen/Core>

#include <array>
#include <functional>

namespace arview::room {

using Sh9 = std::array<double, 9>;
// One Sh9 per colour channel, as 9 RGB triples (R, G, B: linear camera units).
using ShRgb = std::array<Eigen::Vector3d, 9>;

Sh9 ShBasis(const Eigen::Vector3d& unit_direction);

// ∫ radiance(ω) Y(ω) dω by a Fibonacci sphere of `samples` directions (for tests and tools).
ShRgb ProjectRadiance(const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& radiance, int samples);

// Exact coefficients of a uniform cap of `radiance` within `half_angle_rad` of `axis` (Funk–Hecke:
// zonal factors 2π(1 − c), π(1 − c²), π(c − c³) with c = cos half_angle).
ShRgb CapSh(const Eigen::Vector3d& axis, double half_angle_rad, const Eigen::Vector3d& radiance);
// A constant radiance over the whole sphere.
ShRgb ConstantSh(const Eigen::Vector3d& radiance);
ShRgb operator+(const ShRgb& a, const ShRgb& b);
ShRgb Scaled(const ShRgb& sh, const Eigen::Vector3d& per_channel_gain);

// Radiance of the order-2 approximation in a direction.
Eigen::Vector3d EvaluateSh(const ShRgb& sh, const Eigen::Vector3d& unit_direction);
// Irradiance on a surface of normal `n`: Σ Â_l L_lm Y_lm(n), Â = (π, 2π/3, π/4) (Ramamoorthi and
// Hanrahan 2001). A Lambertian surface of albedo ρ then has radiance ρ·E/π.
Eigen::Vector3d IrradianceSh(const ShRgb& sh, const Eigen::Vector3d& unit_normal);

// A directional light plus a constant ambient: direction from band 1 (luminance weights),
// colour c from L_1m = c·Y_1m(d) (band 1 in the least-squares sense), ambient from what band 0
// has left. Exact for one directional light plus constant ambient; band 2 is not fitted, since
// a real room's band 2 need not look like one light's (sh.cpp).
struct DominantLight {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, towards the light
  Eigen::Vector3d color = Eigen::Vector3d::Zero();       // irradiance at normal incidence, RGB
  Eigen::Vector3d ambient = Eigen::Vector3d::Zero();     // radiance, RGB (clamped at 0)
};
DominantLight ExtractDominantLight(const ShRgb& sh);

// Coefficients of f∘Rᵀ (the function rotated by R: f'(R·ω) = f(ω)). Band 1 rotates as a
// vector, band 2 as the symmetric traceless matrix Q of f₂(ω) = ωᵀQω (Q' = R Q Rᵀ): exact, and
// a few multiply-adds, so the vertex shader does the same per vertex.
Sh9 RotateSh(const Sh9& coefficients, const Eigen::Matrix3d& rotation);
ShRgb RotateSh(const ShRgb& coefficients, const Eigen::Matrix3d& rotation);

// Σ a_i b_i per channel: ∫ light · transfer for an Sh9 transfer.
Eigen::Vector3d DotSh(const ShRgb& light, const Sh9& transfer);

// Luminance weights used to find the dominant direction (Rec. 709).
inline Eigen::Vector3d LuminanceWeights() { return {0.2126, 0.7152, 0.0722}; }

}  // namespace arview::room
