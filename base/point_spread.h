#pragma once
// Whether a set of positions spans a plane, absolutely and relatively: the one degeneracy test
// for alignments (EstimateSim3), plane fits and maps (issue 41: positions at one point up to
// rounding, on one line, or scaled by 1e-300 passed a relative test alone).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace arview {

// Positions beyond kMaxPositionNorm of the origin overflow the squares of a fit (1e308 squared is
// inf); spreads below kMinPositionSpread are not told apart from one point (a map scaled by
// 1e-300: the squares of its coordinates underflow to 0).
inline constexpr double kMaxPositionNorm = 1e100;
inline constexpr double kMinPositionSpread = 1e-100;

// How a set of positions spreads: their mean and the standard deviations along their principal
// axes, largest first (computed on the positions scaled to unit extent, so that neither tiny
// nor huge coordinates underflow or overflow). Empty input: zeros.
struct PointSpread {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
};
PointSpread MeasureSpread(const std::vector<Eigen::Vector3d>& points);

// Why `points` do not span a plane, in words for a message, or nothing when they do. A plane
// needs at least 3 finite positions within kMaxPositionNorm, whose largest spread exceeds the
// rounding of their magnitude (1e-8 of their distance from the origin plus their spread) and
// kMinPositionSpread ("all 40 points lie at one point, (1, 2, 3): ..."), and whose second spread
// exceeds 1e-6 of the largest and the same floor ("... lie on one line: ..."). `noun` names
// them in the message ("points", "positions", "camera centres").
std::optional<std::string> WhyNotAPlane(const std::vector<Eigen::Vector3d>& points, const std::string& noun);

}  // namespace arview
