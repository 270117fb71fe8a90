#pragma once
// The tracker's own steps and types, apart from its interface (tracker.h): spreading tracks over
// the image, the motion model, the map check (here so that the tests can reach them), and the
// jobs the tracking thread hands its worker (shared by tracker.cpp, which polls them, and
// tracker_background.cpp, which starts and collects them). Private to tracker/: its sources and
// tests include it, nothing outside.

#include <opencv2/core.hpp>

#include <chrono>
#include <cstdint>
#include <future>
#include <vector>

#include "calib/pose.h"
#include "map/map.h"
#include "tracker/relocalizer.h"
#include "tracker/tracker.h"
#include "tracker/tracking_worker.h"

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

// A frame's guided features being extracted on a worker thread, with what matching them and
// following them into a later frame needs of it.
struct Tracker::Prefetch {
  std::future<TrackingWorker::Extracted> extracted;  // run by worker_
  std::int64_t frame = 0;  // frames_tracked_ of the frame
  calib::Pose pose;        // its pose (working camera)
  std::vector<cv::Mat> pyramid;
  std::vector<std::uint32_t> tracked_points;  // its followed inliers' map points (covisibility)
};

// A relocalization running on the worker (TrackingOptions::background), and the frame it works on.
struct Tracker::Recovery {
  std::future<TrackingWorker::Relocalized> outcome;  // run by worker_
  std::int64_t frame = 0;        // frames_tracked_ of the frame
};

// Whether a job's result has come back; never waits.
template <typename T>
bool Ready(const std::future<T>& future) {
  return future.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

}  // namespace arview::tracker
