#pragma once
// The floor under a map's cameras, which the map's metric frame (mapping/metric_frame.h) stands
// on: the lowest dense plane of the map's points (FindFloor), the frame standing on it
// (FloorFrame) and the cameras' height over it. The camera-height estimate stands on it, and a
// known distance or a board off the floor take up and the origin from it (docs/mapping.md,
// "Metric scale and up"). Internal to mapping/ (mapping/metric_frame.cpp).

#include <Eigen/Core>

#include <vector>

#include "base/geometry.h"
#include "base/plane_fit.h"
#include "map/map.h"

namespace arview::mapping {

// The keyframes' camera centres, in keyframe order.
std::vector<Eigen::Vector3d> Centres(const map::Map& map);

// The floor: a plane near-perpendicular to the cameras' up, its normal turned towards the cameras.
// The dominant plane of all the points first; then, while the points below the plane found
// (along up) hold another plane of at least kFloorShareOfPoints of the points, that one, so that
// the search goes down to the lowest dense plane. `below` receives the fraction of the points
// more than three inlier distances under the floor returned.
Plane FindFloor(const map::Map& map, double* below = nullptr);

// The frame standing on `floor`: z its normal, the origin below the cameras' mean centre, x the
// first keyframe's viewing direction along the floor; `scale` map units → metres.
Sim3 FloorFrame(const map::Map& map, const Plane& floor, double scale);

// The cameras' median height over `floor` (map units; negative when most are below it).
double MedianHeightOverFloor(const map::Map& map, const Plane& floor);

}  // namespace arview::mapping
