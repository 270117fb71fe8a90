#pragma once
// The tracker's own steps, apart from its interface (tracker.h) so that the tests can reach them:
// spreading tracks over the image, the motion model, the map check.

#include <opencv2/core.hpp>

#include "calib/pose.h"
#include "map/map.h"
#include "tracker/relocalizer.h"

namespace arview::tracker {

// At most `max_count` of `tracks`, spread evenly over a grid of `cell` pixel squares (round
// robin over the cells, in input order within a cell).
Track2D3D SpreadTracks(const Track2D3D& tracks, int max_count, int cell, const cv::Size& size);

// Throws TrackerError naming the problem when `map` cannot be tracked against: fewer than
// `min_points` points, or a map that map::ValidateMap refuses.
void CheckTrackable(const map::Map& map, int min_points);

// Constant-velocity prediction: apply the last inter-frame motion once more.
calib::Pose PredictConstantVelocity(const calib::Pose& last, const calib::Pose& velocity);
// `motion` scaled by `ratio` (rotation angle and translation multiplied): the motion over
// ratio times the interval it was measured on.
calib::Pose ScaleMotion(const calib::Pose& motion, double ratio);
// velocity such that PredictConstantVelocity(previous, velocity) == last.
calib::Pose RelativeMotion(const calib::Pose& previous, const calib::Pose& last);

}  // namespace arview::tracker
