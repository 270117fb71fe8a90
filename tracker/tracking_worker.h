#pragma once
// The tracker's worker (TrackingOptions::background and prefetch_below): guided matching's SIFT
// extracted ahead, and relocalization, on the worker thread (`arview-trackwk`, tracker/worker.h),
// so that the tracking thread need not wait for them (docs/tracker.md, "The tracking worker").
//
// Which thread may touch what:
//   - The tracking thread (the one calling Tracker::Track; one at a time) constructs and destroys
//     it and calls every public method. Their results come back only through the futures, which
//     the tracking thread alone holds and reads.
//   - The worker thread runs the jobs. A job touches only its own copy of the frame and this
//     class's members: the relocalizer and the SIFT extractor it owns (no other thread uses
//     them: the tracking thread has its own), the flow settings (constant).
//   - Both threads read the map and its descriptor index, which nobody writes while a tracker
//     exists (a built FLANN index's search keeps its state per call).
//   - Destroying it finishes a running job, and drops a waiting one (its future reports a broken
//     promise).

#include <future>
#include <vector>

#include <opencv2/core.hpp>

#include "map/descriptor_index.h"
#include "map/map.h"
#include "tracker/features.h"
#include "tracker/relocalizer.h"
#include "tracker/worker.h"

namespace arview::tracker {

// A frame's image pyramid for pyramidal LK: `window_px` square windows, `levels` levels.
std::vector<cv::Mat> FlowPyramid(const cv::Mat& gray, int window_px, int levels);

class TrackingWorker {
 public:
  // Guided matching's SIFT extracted ahead of the frame that uses it.
  struct Extracted {
    Features features;
    double cpu_ms = 0;  // the worker's CPU time
  };
  // A relocalization and the frame's flow pyramid, for following its inliers into a later frame.
  struct Relocalized {
    RelocalizationResult relocalization;
    std::vector<cv::Mat> pyramid;  // empty when the relocalization failed
    double cpu_ms = 0;             // the worker's CPU time
  };
  struct FlowSettings {
    int window_px = 21;
    int levels = 3;
  };

  // `map` and `index` must outlive it. `camera`: the tracker's working camera; `relocalization`
  // and `guided_features`: the tracker's settings, so that the worker's results are those the
  // tracking thread would have had.
  TrackingWorker(const map::Map& map, const calib::Camera& camera, const map::DescriptorIndex& index,
                 const RelocalizerOptions& relocalization, const FeatureOptions& guided_features, FlowSettings flow);
  TrackingWorker(const TrackingWorker&) = delete;
  TrackingWorker& operator=(const TrackingWorker&) = delete;

  // Guided matching's SIFT of `gray` (the working camera's size; copied: the caller may reuse
  // its buffer), once the running job is done. A job submitted earlier that has not started yet
  // is dropped (Worker::Submit).
  std::future<Extracted> ExtractAhead(const cv::Mat& gray);
  // `gray` relocalised, likewise.
  std::future<Relocalized> Relocalize(const cv::Mat& gray);

 private:
  const Relocalizer relocalizer_;         // the worker's own
  const SiftExtractor guided_extractor_;  // the worker's own, guided matching's settings
  const FlowSettings flow_;
  Worker thread_;  // last: destroyed first, so that a running job finishes while the members it uses exist
};

}  // namespace arview::tracker
