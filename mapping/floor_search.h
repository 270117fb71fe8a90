#pragma once
// The floor under a map's cameras, which the map's metric frame (mapping/metric_frame.h) stands
// on: the lowest dense plane of the map's points (FindFloor), the frame standing on it
// (FloorFrame) and the cameras' height over it. The camera-height estimate stands on it, and a
// known distance or a board off the floor take up and the origin from it (docs/mapping.md,
// "Metric scale and up"). Internal to mapping/ (mapping/metric_frame.cpp).

#include <Eigen/Core>

#include <vector>

#include "base/geometry.h"
#include "base/lowest_floor.h"
#include "map/map.h"

namespace arview::mapping {

// The keyframes' camera centres, in keyframe order.
std::vector<Eigen::Vector3d> Centres(const map::Map& map);

// The floor: base/lowest_floor.h's FindLowestFloor on the map's points and keyframes (the lowest
// dense plane near-perpendicular to the cameras' up, its normal turned towards them). `below`
// receives the fraction of the points more than three inlier distances under it. Throws
// map::MapError ("no floor found in the map's points: ...").
Plane FindFloor(const map::Map& map, double* below = nullptr);

// The frame standing on `floor`: z its normal, the origin below the cameras' mean centre, x the
// first keyframe's viewing direction along the floor; `scale` map units → metres.
Sim3 FloorFrame(const map::Map& map, const Plane& floor, double scale);

// The cameras' median height over `floor` (map units; negative when most are below it).
double MedianHeightOverFloor(const map::Map& map, const Plane& floor);

}  // namespace arview::mapping
