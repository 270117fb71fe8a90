// The tracker's side of its worker (tracker/tracking_worker.h, TrackingOptions::background and
// prefetch_below), apart from tracker.cpp: handing guided matching's SIFT extraction and
// relocalization to the worker thread, and taking their results back on the tracking thread
// without waiting for them (docs/tracker.md, "The tracking worker"). The jobs' types are in
// tracker_internal.h, as Track() in tracker.cpp polls them too.

#include <chrono>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "tracker/timing.h"
#include "tracker/tracker.h"
#include "tracker/tracker_internal.h"

namespace arview::tracker {

void Tracker::MaybePrefetch(const cv::Mat& gray, const FrameResult& result) {
  const TrackingOptions& opt = options_.tracking;
  if (opt.prefetch_below <= 0 || prefetch_ || recovery_ || result.status == TrackStatus::kLost) return;
  // After a relocalization always: its inliers are relocalization's keypoints, which flow
  // follows less exactly (relocalization_keypoints_followed_), and it may be followed only thinly.
  const bool fresh_tracks_wanted = opt.background && result.status == TrackStatus::kRelocalized;
  if (result.status != TrackStatus::kTracking && !fresh_tracks_wanted) return;
  // Or when the tracks are thinning, or the next frame is due a re-search by age
  // (ResearchTriggerOptions::max_frames_between).
  const bool thinning = static_cast<int>(last_inliers_.pixels.size()) < opt.prefetch_below;
  if (!fresh_tracks_wanted && !thinning && !research_trigger_.AgeDue(frame_counter_ + 1)) return;
  if (last_pyramid_.empty()) return;
  auto prefetch = std::make_unique<Prefetch>();
  prefetch->frame = frames_tracked_;
  prefetch->pose = result.pose;
  prefetch->pyramid = last_pyramid_;  // shares the images: the next frame builds its own
  prefetch->tracked_points = last_inliers_.points;
  prefetch->extracted = worker_->ExtractAhead(gray);
  prefetch_ = std::move(prefetch);
}

int Tracker::UsePrefetch(const std::vector<cv::Mat>& pyramid, const calib::Pose& projecting, FrameResult* result,
                         Correspondences* correspondences) {
  const TrackingOptions& opt = options_.tracking;
  const calib::Camera& camera = resolution_.work();
  const std::unique_ptr<Prefetch> prefetch = std::move(prefetch_);
  const TrackingWorker::Extracted extracted = prefetch->extracted.get();
  result->keypoints = static_cast<int>(extracted.features.keypoints.size());
  result->times.extract_ms += extracted.cpu_ms;
  result->times.cpu_ms += extracted.cpu_ms;  // Track() adds its own thread's
  const auto match_start = std::chrono::steady_clock::now();
  // The map points the prefetched frame's neighbours see, projected with its own pose.
  const std::vector<GuidedCandidate> candidates = GuidedCandidates(prefetch->pose, prefetch->tracked_points);
  const auto matches = MatchGuided(extracted.features, candidates, map_, opt.guided_radius_px, opt.guided_ratio,
                                     camera.Size());
  // Followed from the prefetched frame into this one, started where this frame's pose puts them;
  // only as many, spread over the picture, as the flow follows (LK costs ~10 us a point).
  Track2D3D matched;
  for (const auto& m : matches) {
    matched.pixels.push_back(extracted.features.keypoints[m.keypoint].pt);
    matched.points.push_back(m.point);
  }
  matched = SpreadTracks(matched, opt.max_flow_tracks, opt.flow_grid_cell_px, camera.Size());
  std::vector<cv::Point2f> to;
  std::vector<Eigen::Vector2d> expected;
  for (size_t i = 0; i < matched.pixels.size(); ++i) {
    const Eigen::Vector3d pc = projecting.ToCamera(map_.points[matched.points[i]].xyz);
    const Eigen::Vector2d px = pc.z() > 0 ? camera.Project(pc) : Eigen::Vector2d(-1, -1);
    expected.push_back(px);
    to.push_back(camera.InImage(px) ? cv::Point2f(px.x(), px.y()) : matched.pixels[i]);
  }
  // A track that ends far from where the pose puts its point slid onto something else.
  const int added = FollowIntoFrame(prefetch->pyramid, pyramid, matched.pixels, matched.points, std::move(to),
                                    correspondences, [&](std::size_t i, const Eigen::Vector2d& px) {
                                      return (px - expected[i]).norm() <= opt.guided_radius_predicted_px;
                                    });
  result->prefetched_matches = added;
  result->guided_matches += added;
  result->times.match_ms += MillisecondsSince(match_start);
  return added;  // (the LK above is counted with the matching)
}

Track2D3D Tracker::TrackWithoutWaiting(const cv::Mat& gray, double timestamp, FrameResult* result) {
  Track2D3D inliers;
  // 1. A relocalization the worker finished, followed into this frame.
  if (recovery_ && Ready(recovery_->outcome)) {
    if (FinishRecovery(gray, result, &inliers)) {
      result->status = TrackStatus::kRelocalized;
      return inliers;
    }
    inliers = {};
  }
  // 2. The prior: flow, and the guided matches extracted ahead when they are done.
  if (has_pose_) {
    const std::vector<cv::Mat> reference_pyramid = last_pyramid_;  // the last posed frame's (shared)
    std::optional<Features> none;  // nothing is extracted on this thread
    if (TrackWithPrior(gray, timestamp, result, &none, &inliers)) {
      result->status = TrackStatus::kTracking;
      result->reason.clear();
      return inliers;
    }
    inliers = {};
    // 3. A whip-pan: the rotation by image alignment while the worker relocalises.
    if (TrackByAlignment(reference_pyramid, gray, timestamp, result)) {
      result->status = TrackStatus::kTracking;
      result->inliers = 0;
      result->rms_px = 0;
      StartRecovery(gray);
      return inliers;
    }
  }
  // 4. Lost: relocalised on the worker; this frame is not waited for.
  StartRecovery(gray);
  result->status = TrackStatus::kLost;
  result->inliers = 0;
  result->awaiting_relocalization = result->relocalization_failure == PoseFailure::kNone;
  std::ostringstream msg;
  msg << (result->reason.empty() ? "" : "; ") << "relocalization running in the background since "
      << frames_tracked_ - recovery_->frame << " frame(s) ago";
  result->reason += msg.str();
  return inliers;
}

void Tracker::StartRecovery(const cv::Mat& gray) {
  if (recovery_) return;
  prefetch_.reset();  // its features would come after the relocalization's
  auto recovery = std::make_unique<Recovery>();
  recovery->frame = frames_tracked_;
  recovery->outcome = worker_->Relocalize(gray);
  recovery_ = std::move(recovery);
}

bool Tracker::FinishRecovery(const cv::Mat& gray, FrameResult* result, Track2D3D* inliers) {
  const std::unique_ptr<Recovery> recovery = std::move(recovery_);
  const TrackingWorker::Relocalized outcome = recovery->outcome.get();
  const RelocalizationResult& reloc = outcome.relocalization;
  result->keypoints = reloc.keypoints;
  result->matches = reloc.matches;
  result->times.extract_ms += reloc.extract_ms;  // the worker's
  result->times.cpu_ms += outcome.cpu_ms;
  result->relocalized_frames_ago = static_cast<int>(frames_tracked_ - recovery->frame);
  if (!reloc.pose.ok) {
    result->reason = "relocalization failed: " + reloc.pose.reason;
    result->relocalization_failure = reloc.pose.failure;
    return false;
  }
  // The relocalization's inliers followed from its frame into this one, started where they were:
  // the camera moved little in the frames it took.
  const auto flow_start = std::chrono::steady_clock::now();
  std::vector<cv::Mat> pyramid = FlowPyramid(gray);
  Correspondences c;
  FollowIntoFrame(outcome.pyramid, pyramid, reloc.inliers.pixels, reloc.inliers.points, reloc.inliers.pixels, &c);
  result->flow_tracks = static_cast<int>(c.pixels.size());
  result->times.flow_ms += MillisecondsSince(flow_start);
  AbsolutePoseOptions pose_options = TrackedPoseOptions(options_.tracking.ransac_max_iterations);
  pose_options.max_rms_px = options_.relocalization.pose.max_rms_px;  // no recent tracked frames to gate by
  pose_options.prior = reloc.pose.pose;
  const AbsolutePoseResult pose = PoseFromPrior(c, pose_options, result).pose;
  if (!pose.ok) {
    std::ostringstream msg;
    msg << "relocalised " << result->relocalized_frames_ago << " frame(s) before, its " << reloc.inliers.pixels.size()
        << " inliers followed into this frame: " << pose.reason;
    result->reason = msg.str();
    return false;
  }
  result->pose = pose.pose;
  for (int i : pose.inliers) {
    inliers->pixels.emplace_back(c.pixels[i].x(), c.pixels[i].y());
    inliers->points.push_back(c.point_ids[i]);
  }
  last_pyramid_ = std::move(pyramid);
  return true;
}

}  // namespace arview::tracker
