// Tracker (tracker.h): construction, the per-frame Track() and the steps it runs in line (the
// prior from flow and guided matching, the wide search, image alignment, relocalization, the
// refinement on the full camera). Apart from it: the hand-off to the worker in
// tracker_background.cpp, the flow in tracker_flow.cpp, guided matching's search in
// guided_matching.cpp, the hidden points and the moving-track filter in tracker_hidden.cpp and
// tracker_moving.cpp.

#include "tracker/tracker.h"

#include "tracker/brightness_match.h"
#include "tracker/tracker_internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "map/map_file.h"
#include "tracker/refine_pose.h"
#include "tracker/timing.h"

namespace arview::tracker {
namespace {

void CopyStats(const AbsolutePoseResult& pose, FrameResult* result) {
  result->inliers = pose.stats.inliers;
  result->rms_px = pose.stats.rms_px;
  result->times.ransac_ms += pose.stats.ransac_ms;
  result->times.refine_ms += pose.stats.refine_ms;
}

// The options, once they passed their Check(): the tracker's members are built from them.
const TrackerOptions& Checked(const TrackerOptions& options) {
  options.Check(OptionNames().Nested("tracker"));
  return options;
}

}  // namespace

Tracker::Tracker(const map::Map& map, const TrackerOptions& options) : Tracker(map, map.camera, options) {}

Tracker::Tracker(const map::Map& map, const calib::Camera& camera, const TrackerOptions& options)
    : map_(map),
      options_(Checked(options)),  // before any member is built from them
      resolution_(camera, options.working_long_side),
      rms_gate_(options.tracking.rms_gate),
      smoother_(options.smoothing),
      moving_filter_(options.tracking.moving, map.points.size()),
      research_trigger_(options.tracking.research, options.tracking.replenish_below) {
  CheckTrackable(map, options.min_map_points);
  index_ = options.index_cache_folder.empty()
               ? map::DescriptorIndex(map.descriptors, options.index)
               : map::DescriptorIndex::Cached(map.descriptors, options.index, options.index_cache_folder, &index_note_);
  relocalizer_ = std::make_unique<Relocalizer>(map_, resolution_.work(), index_, options.relocalization);
  FeatureOptions guided_features = options.relocalization.features;
  guided_features.max_features = options.tracking.guided_max_features;
  guided_features.contrast_threshold = options.tracking.guided_contrast_threshold;
  guided_extractor_ = std::make_unique<SiftExtractor>(guided_features);
  relocalization_keypoints_followed_ = ActiveFeatures(resolution_.work(), options.relocalization).contrast_threshold >=
                                       options.tracking.guided_contrast_threshold;
  if (options.tracking.background || options.tracking.prefetch_below > 0) {
    worker_ = std::make_unique<TrackingWorker>(map_, resolution_.work(), index_, options.relocalization, guided_features,
                                               TrackingWorker::FlowSettings{options.tracking.lk_window_px,
                                                                            options.tracking.lk_pyramid_levels});
  }
  point_stamp_.assign(map.points.size(), 0);
  point_keyframes_.resize(map.points.size());
  for (size_t k = 0; k < map.keyframes.size(); ++k)
    for (const auto& obs : map.keyframes[k].observations)
      point_keyframes_[obs.point].push_back(static_cast<std::uint32_t>(k));
}

Tracker::~Tracker() = default;  // worker_, destroyed first, finishes a running job

void Tracker::WarmUp() {
  const cv::Mat blank(resolution_.work().Size(), CV_8U, cv::Scalar(0));
  const RelocalizationResult nothing = relocalizer_->Relocalize(blank);  // its own SIFT size
  const Features none = relocalizer_->Extract(blank, *guided_extractor_);  // guided matching's
  const std::vector<cv::Mat> pyramid = FlowPyramid(blank);
  const std::vector<map::Neighbor> nearest = index_.Knn(map_.descriptors.ptr<std::uint8_t>(0), 1);
  (void)nothing, (void)none, (void)pyramid, (void)nearest;
}

void Tracker::Reset() {
  recovery_.reset();  // its result, when it comes, is dropped with the future
  ForgetPrior();
}

void Tracker::ForgetPrior() {
  prefetch_.reset();
  feature_centres_.Clear();
  has_pose_ = false;
  has_velocity_ = false;
  last_pyramid_.clear();
  last_light_gain_ = 1;
  last_light_switch_timestamp_ = -std::numeric_limits<double>::infinity();
  last_inliers_ = {};
  hidden_.Clear();
  research_trigger_.Clear();
  smoother_.Reset();
}

Tracker::PriorPose Tracker::PoseFromPrior(const Correspondences& c, AbsolutePoseOptions options,
                                          FrameResult* result) const {
  const calib::Camera& camera = resolution_.work();
  PriorPose out;
  out.pose = EstimateAbsolutePose(camera, c.pixels, c.points, options);
  CopyStats(out.pose, result);
  if (!out.pose.ok ||
      out.pose.stats.inliers < options_.tracking.prior_min_inlier_ratio * static_cast<double>(c.pixels.size())) {
    options.prior.reset();
    out.pose = EstimateAbsolutePose(camera, c.pixels, c.points, options);
    CopyStats(out.pose, result);
    out.prior_dropped = true;
  }
  return out;
}

calib::Pose Tracker::Predict(double timestamp) const {
  if (!has_velocity_) return last_pose_;
  const double dt = timestamp - last_timestamp_;
  double ratio = 1;
  if (std::isfinite(dt) && dt > 0 && velocity_dt_ > 0)
    ratio = std::min(dt / velocity_dt_, options_.tracking.max_prediction_ratio);
  return PredictConstantVelocity(last_pose_, ScaleMotion(velocity_, ratio));
}

bool Tracker::TrackWithPrior(const cv::Mat& gray, double timestamp, FrameResult* result,
                             std::optional<Features>* extracted, Track2D3D* tracked_inliers) {
  const TrackingOptions& opt = options_.tracking;
  const calib::Camera& camera = resolution_.work();
  const calib::Pose predicted = Predict(timestamp);

  // 1. Pyramidal LK from last frame's inliers, started where the prediction puts them.
  const auto flow_start = std::chrono::steady_clock::now();
  const BrightnessMatch lit =
      MatchMeanBrightness(gray, last_pyramid_.empty() ? cv::Mat() : last_pyramid_[0], opt.flow_brightness_tolerance);
  std::vector<cv::Mat> pyramid = FlowPyramid(lit.image);
  Correspondences c;
  ++frame_counter_;
  MovingTrackVerdict moving;
  std::vector<float> lk_errors;  // LK's patch error of each surviving track
  if (!last_inliers_.pixels.empty() && !last_pyramid_.empty()) {
    std::vector<cv::Point2f> guess;
    std::vector<bool> in_view;  // the prediction puts the track's point in the picture
    guess.reserve(last_inliers_.pixels.size());
    for (size_t i = 0; i < last_inliers_.pixels.size(); ++i) {
      const Eigen::Vector3d pc = predicted.ToCamera(map_.points[last_inliers_.points[i]].xyz);
      const Eigen::Vector2d px = pc.z() > 0 ? camera.Project(pc) : Eigen::Vector2d(-1, -1);
      in_view.push_back(camera.InImage(px));
      guess.push_back(in_view.back() ? cv::Point2f(px.x(), px.y()) : last_inliers_.pixels[i]);
    }
    std::vector<double> motion_px;  // each surviving track's move from the last frame
    std::vector<Eigen::Vector2d> predicted_px;  // where the prediction puts each surviving track
    int followed_in_view = 0;
    FollowIntoFrame(last_pyramid_, pyramid, last_inliers_.pixels, last_inliers_.points, guess, &c,
                    [&](std::size_t i, const Eigen::Vector2d& px) {
                      if (in_view[i]) ++followed_in_view;
                      motion_px.push_back((px - Eigen::Vector2d(last_inliers_.pixels[i].x, last_inliers_.pixels[i].y)).norm());
                      predicted_px.emplace_back(guess[i].x, guess[i].y);
                      return true;
                    },
                    &lk_errors);
    result->flow_followed_from = static_cast<int>(last_inliers_.pixels.size());
    result->flow_lost_in_view = static_cast<int>(std::count(in_view.begin(), in_view.end(), true)) -
                                followed_in_view;
    moving = DropMovingTracks(predicted_px, lk_errors, &c, result);
    DropClippedTracks(gray, 0, &c, result);
    research_trigger_.Occluded(frame_counter_, moving.by_patch);
    for (const std::uint32_t id : c.point_ids) point_stamp_[id] = frame_counter_;
    HideLostTracks(in_view);
    if (!motion_px.empty()) {
      std::nth_element(motion_px.begin(), motion_px.begin() + motion_px.size() / 2, motion_px.end());
      result->flow_motion_px = motion_px[motion_px.size() / 2];
    }
  }
  result->flow_tracks = static_cast<int>(c.pixels.size());
  result->times.flow_ms = MillisecondsSince(flow_start);

  AbsolutePoseOptions pose_options = TrackedPoseOptions(opt.ransac_max_iterations);
  pose_options.prior = predicted;
  // Under a light change the gate learnt on steady frames is too tight: a lamp switched on under
  // an exposure raised for the dark clips the frame, and its poses fit at 1.15-1.45 px against a
  // 1 px gate; refused, they were relocalised one by one (docs/tracker.md, "People walking
  // through and lights changing"). Such a frame is held to the gate's upper bound instead.
  // Only the frames whose light changed from the last one's: the scaling goes on for as long as
  // the light stays changed, and a gate open all that while let drifted poses through.
  // A light switched (a step of `light_switch_ev` or more: the lamp) keeps the gate open
  // `light_switch_hold_s`: an auto-exposure then steps back on frames still clipped white, which
  // fit at 1.1-1.4 px too (nine relocalizations without the hold). Not after the exposure's own
  // steps (1/3 EV): held after each, the gate stayed open through its whole ramp and let drifted
  // poses through (docs/tracker.md, "Third round").
  const double light_step = lit.gain / last_light_gain_;
  last_light_gain_ = lit.gain;
  const bool light_switched = std::abs(std::log2(light_step)) >= opt.light_switch_ev;
  if (light_switched) last_light_switch_timestamp_ = timestamp;
  if (std::abs(light_step - 1) > opt.flow_brightness_tolerance || LightSwitchHeld(timestamp))
    pose_options.max_rms_px = std::max(pose_options.max_rms_px, rms_gate_.options().max_px);
  result->rms_gate_px = pose_options.max_rms_px;

  // 2. Guided matching when the flow tracks have thinned out: map points projected with the
  // pose the surviving tracks give (closer than the prediction after a large or sudden
  // motion), or with the prediction and a wider radius when too few tracks survive.
  // A prefetched frame is used `prefetch_lag_frames` after it, or as soon as the tracks thin out.
  // With `background` it is used as soon as it is done, and nothing is extracted here.
  // Thinning: under replenish_below, less the tracks a walker took that are expected back
  // (tracker/research_trigger.h).
  const bool thinning = research_trigger_.Due(frame_counter_, c.pixels, camera.Size());
  const bool prefetch_due =
      prefetch_ && (opt.background ? Ready(prefetch_->extracted)
                                   : frames_tracked_ - prefetch_->frame >= opt.prefetch_lag_frames || thinning);
  // The pose the surviving tracks give, when enough survive (what guided matching and the hidden
  // points are projected with).
  std::optional<calib::Pose> from_flow;
  if ((prefetch_due || thinning) && result->flow_tracks >= opt.min_inliers) {
    const AbsolutePoseResult flow_pose = EstimateAbsolutePose(camera, c.pixels, c.points, pose_options);
    result->times.refine_ms += flow_pose.stats.refine_ms;
    if (flow_pose.ok) from_flow = flow_pose.pose;
  }
  // Tracks thinned by someone walking through: the points they hid followed back first.
  if (thinning && from_flow) result->recovered_tracks = RecoverHiddenPoints(pyramid, *from_flow, lk_errors, &c);
  // Not on the frame a light switched on or off while the flow still pins the pose: its SIFT sees
  // the new light (a lamp on under a raised exposure clips, and guided matches sit on the white
  // blobs' edges); the next frame searches instead.
  const bool search_next_frame = light_switched && result->flow_tracks >= opt.min_inliers;
  const bool extract_here =
      !opt.background && !search_next_frame && research_trigger_.Due(frame_counter_, c.pixels, camera.Size());
  const std::size_t before_search = c.pixels.size();  // the flow tracks and the hidden points followed back
  if (prefetch_due || extract_here) {
    research_trigger_.Searched(frame_counter_);
    const calib::Pose projecting = from_flow.value_or(predicted);
    const double radius = from_flow ? opt.guided_radius_px : opt.guided_radius_predicted_px;
    if (prefetch_due) {
      UsePrefetch(pyramid, projecting, result, &c);
    } else {
      const auto extract_start = std::chrono::steady_clock::now();
      // Fewer flow tracks than a pose needs (a jump, a blurred frame): the frame is likely to end
      // in a relocalization. On a reduced frame its features are then relocalization's own (a
      // smaller image, its settings), so that such a frame costs one extraction of relocalization's
      // size, not guided matching's and then relocalization's on top of it (phone-fox's frame 18:
      // 180 -> 84 ms). Not when the flow kept enough tracks but no pose fits them: there the wide
      // search usually succeeds, and with guided matching's features its pose is closer
      // (phone-fox's wide-search frames at 480 px: max centre error 0.021 -> 0.026 units).
      const bool flow_collapsed = result->flow_tracks < opt.min_inliers;
      const Features& features = extracted->emplace(flow_collapsed && relocalizer_->OwnExtractionSmaller()
                                                        ? relocalizer_->ExtractOwn(gray)
                                                        : relocalizer_->Extract(gray, *guided_extractor_));
      result->keypoints = static_cast<int>(features.keypoints.size());
      result->times.extract_ms = MillisecondsSince(extract_start);
      const auto match_start = std::chrono::steady_clock::now();
      const std::vector<GuidedCandidate> candidates = GuidedCandidates(projecting, c.point_ids);
      const auto guided = MatchGuided(features, candidates, map_, radius, opt.guided_ratio, gray.size());
      for (const auto& m : guided) {
        const cv::Point2f& p = features.keypoints[m.keypoint].pt;
        c.pixels.emplace_back(p.x, p.y);
        c.points.push_back(map_.points[m.point].xyz);
        c.point_ids.push_back(m.point);
      }
      result->guided_matches = static_cast<int>(guided.size());
      result->times.match_ms = MillisecondsSince(match_start);
    }
  }

  // Guided matches on clipped windows: keypoints on the edges of the white blobs, not the texture's.
  DropClippedTracks(gray, before_search, &c, result);
  DropNearMoving(moving, static_cast<std::size_t>(result->flow_tracks), &c, result);

  // 3. Refinement from the prediction; when it explains too few correspondences, a short
  // RANSAC, whose pose must stay near the prediction.
  const PriorPose from_prior = PoseFromPrior(c, pose_options, result);
  const AbsolutePoseResult& pose = from_prior.pose;
  last_pyramid_ = std::move(pyramid);
  if (from_prior.prior_dropped) {
    if (pose.ok) {
      const double jump_deg = pose.pose.q_cw.angularDistance(predicted.q_cw) * 180.0 / M_PI;
      if (jump_deg > opt.max_rotation_from_prediction_deg) {
        std::ostringstream msg;
        msg << "tracking failed: RANSAC pose turns " << jump_deg << " deg from the prediction";
        result->reason = msg.str();
        return false;
      }
    }
  }
  if (!pose.ok) {
    result->reason = "tracking failed: " + pose.reason;
    return false;
  }
  result->pose = pose.pose;
  Track2D3D& inliers = *tracked_inliers;
  result->flow_outliers = result->flow_tracks - static_cast<int>(std::count_if(
      pose.inliers.begin(), pose.inliers.end(), [&](int i) { return i < result->flow_tracks; }));
  for (int i : pose.inliers) {
    inliers.pixels.emplace_back(c.pixels[i].x(), c.pixels[i].y());
    inliers.points.push_back(c.point_ids[i]);
  }
  return true;
}

bool Tracker::TrackByAlignment(const std::vector<cv::Mat>& reference_pyramid, const cv::Mat& gray,
                               double timestamp, FrameResult* result) const {
  const TrackingOptions& opt = options_.tracking;
  if (opt.align_max_seconds <= 0 || reference_pyramid.empty()) return false;
  std::ostringstream msg;
  const double since_features = timestamp - last_feature_timestamp_;
  if (!(since_features <= opt.align_max_seconds)) {
    msg << "; image alignment not tried: " << since_features << " s since the last pose from features, at most "
        << opt.align_max_seconds << " s";
    result->reason += msg.str();
    return false;
  }
  const calib::Pose predicted = Predict(timestamp);
  const Eigen::Quaterniond initial = predicted.q_cw * last_pose_.q_cw.conjugate();
  const SmallImage reference(reference_pyramid.front(), resolution_.work(), opt.align);
  const SmallImage current(gray, resolution_.work(), opt.align);
  const RotationAlignment aligned = AlignRotation(reference, current, initial, opt.align);
  if (!aligned.ok) {
    result->reason += "; " + aligned.reason;
    return false;
  }
  const double from_prediction_deg = aligned.rotation.angularDistance(initial) * 180.0 / M_PI;
  if (from_prediction_deg > opt.align_max_from_prediction_deg) {
    msg << "; image alignment turns " << from_prediction_deg << " deg from the prediction, at most "
        << opt.align_max_from_prediction_deg;
    result->reason += msg.str();
    return false;
  }
  result->pose.q_cw = (aligned.rotation * last_pose_.q_cw).normalized();
  const Eigen::Vector3d centre = feature_centres_.empty() ? predicted.Center() : feature_centres_.At(timestamp);
  result->pose.t_cw = -(result->pose.q_cw * centre);
  result->align_zncc = aligned.zncc;
  result->reason += "; rotation by image alignment";
  return true;
}

AbsolutePoseOptions Tracker::TrackedPoseOptions(int ransac_iterations) const {
  const TrackingOptions& opt = options_.tracking;
  AbsolutePoseOptions pose_options = options_.relocalization.pose;
  pose_options.ransac_max_iterations = ransac_iterations;
  pose_options.ransac_threshold_px = opt.ransac_threshold_px;
  pose_options.refinement.loss_scale_px = opt.refine_loss_scale_px;
  pose_options.min_inliers = opt.min_inliers;
  pose_options.max_rms_px = rms_gate_.Gate();
  pose_options.seed += frame_counter_;
  return pose_options;
}

bool Tracker::TrackWide(const cv::Mat& gray, double timestamp, FrameResult* result,
                        std::optional<Features>* extracted, Track2D3D* tracked_inliers) {
  const TrackingOptions& opt = options_.tracking;
  if (opt.wide_radius_fraction <= 0) return false;
  const calib::Camera& camera = resolution_.work();
  const calib::Pose predicted = Predict(timestamp);
  if (!*extracted) {
    const auto extract_start = std::chrono::steady_clock::now();
    // Guided matching's features (a relocalization that follows reuses them): the wide search
    // is guided matching over a wider radius, and has a prior. Relocalization's own SIFT at the
    // frame's own size is tuned for frames without one (RelocalizerOptions::features).
    extracted->emplace(relocalizer_->Extract(gray, *guided_extractor_));
    result->keypoints = static_cast<int>((*extracted)->keypoints.size());
    result->times.extract_ms += MillisecondsSince(extract_start);
  }
  const Features& features = **extracted;
  const auto match_start = std::chrono::steady_clock::now();
  const double radius = opt.wide_radius_fraction * std::max(camera.width, camera.height);
  // Keyframes near the last pose and near the prediction: one of the two is near the truth.
  std::vector<int> keyframes = NearestKeyframes(last_pose_);
  for (int k : NearestKeyframes(predicted))
    if (std::find(keyframes.begin(), keyframes.end(), k) == keyframes.end()) keyframes.push_back(k);
  ++frame_counter_;  // a fresh stamp: points gathered by TrackWithPrior are candidates again
  std::vector<GuidedCandidate> candidates;
  for (int k : keyframes) {
    for (const auto& obs : map_.keyframes[k].observations) {
      if (point_stamp_[obs.point] == frame_counter_) continue;
      point_stamp_[obs.point] = frame_counter_;
      const Eigen::Vector3d pc = predicted.ToCamera(map_.points[obs.point].xyz);
      if (pc.z() <= 0) continue;
      const Eigen::Vector2d px = camera.Project(pc);
      // A point predicted just outside the picture may be inside it: the prediction is off.
      if (px.x() < -radius || px.y() < -radius || px.x() > camera.width + radius ||
          px.y() > camera.height + radius)
        continue;
      // One descriptor a point, its view from the nearest keyframe (keyframes come nearest
      // first): the search reaches across a third of the image, and comparing every view of
      // every point there cost up to 420 ms a frame on phone-fox's default map (5.4 views a point).
      candidates.push_back({px, obs.point, obs.descriptor});
    }
  }
  const auto matches = MatchGuided(features, candidates, map_, radius, opt.wide_ratio, gray.size());
  result->wide_matches = static_cast<int>(matches.size());
  result->times.match_ms += MillisecondsSince(match_start);

  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  GatherCorrespondences(features, map_, matches, &pixels, &points);
  const AbsolutePoseOptions pose_options = TrackedPoseOptions(opt.wide_ransac_iterations);
  const AbsolutePoseResult pose = EstimateAbsolutePose(camera, pixels, points, pose_options);
  CopyStats(pose, result);
  if (!pose.ok) {
    result->reason += "; wide search: " + pose.reason;
    return false;
  }
  const double jump_deg = std::min(pose.pose.q_cw.angularDistance(predicted.q_cw),
                                   pose.pose.q_cw.angularDistance(last_pose_.q_cw)) * 180.0 / M_PI;
  if (jump_deg > opt.wide_max_rotation_deg) {
    std::ostringstream msg;
    msg << "; wide search: pose turns " << jump_deg << " deg from the last pose and the prediction";
    result->reason += msg.str();
    return false;
  }
  result->pose = pose.pose;
  for (int i : pose.inliers) {
    tracked_inliers->pixels.emplace_back(pixels[i].x(), pixels[i].y());
    tracked_inliers->points.push_back(matches[i].point);
  }
  return true;
}

void Tracker::PoseFromFreshFeatures(const cv::Mat& gray, FrameResult* result, std::optional<Features>* features,
                                    Track2D3D* inliers) const {
  const TrackingOptions& opt = options_.tracking;
  // A frame the flow posed alone has no SIFT yet: on a reduced frame relocalization's own, on a
  // smaller image still (phone-fox: 480 px, guided matching's threshold, so the flow may follow
  // its keypoints), is as exact and cheaper (median of three maps 0.00200 -> 0.00191 units);
  // at the frame's own size (or with relocalization's threshold below guided matching's)
  // guided matching's, as relocalization's are then weaker than the flow should follow
  // (relocalization_keypoints_followed_).
  if (!*features && !(relocalizer_->OwnExtractionSmaller() && relocalization_keypoints_followed_)) {
    const auto extract_start = std::chrono::steady_clock::now();
    features->emplace(relocalizer_->Extract(gray, *guided_extractor_));
    result->keypoints = static_cast<int>((*features)->keypoints.size());
    result->times.extract_ms += MillisecondsSince(extract_start);
  }
  const RelocalizationResult fresh = *features ? relocalizer_->Relocalize(**features) : relocalizer_->Relocalize(gray);
  if (!*features) {
    result->keypoints = fresh.keypoints;
    result->times.extract_ms += fresh.extract_ms;
  }
  result->matches = fresh.matches;
  result->times.match_ms += fresh.match_ms;
  result->times.ransac_ms += fresh.pose.stats.ransac_ms;
  result->times.refine_ms += fresh.pose.stats.refine_ms;
  if (!fresh.pose.ok || fresh.pose.stats.inliers < opt.min_inliers) return;
  const double turn_deg = fresh.pose.pose.q_cw.angularDistance(result->pose.q_cw) * 180.0 / M_PI;
  if (turn_deg > opt.fresh_max_rotation_deg) return;
  result->pose = fresh.pose.pose;
  result->inliers = fresh.pose.stats.inliers;
  result->rms_px = fresh.pose.stats.rms_px;
  result->fresh_inliers = fresh.pose.stats.inliers;
  *inliers = fresh.inliers;
}

void Tracker::RefineOnFullCamera(const Track2D3D& inliers, FrameResult* result) const {
  if (!resolution_.reduced() || !options_.refine_on_full_camera || inliers.pixels.empty()) return;
  const auto start = std::chrono::steady_clock::now();
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  pixels.reserve(inliers.pixels.size());
  points.reserve(inliers.pixels.size());
  for (size_t i = 0; i < inliers.pixels.size(); ++i) {
    pixels.push_back(resolution_.ToFull({inliers.pixels[i].x, inliers.pixels[i].y}));
    points.push_back(map_.points[inliers.points[i]].xyz);
  }
  // The loss of the step that posed the frame, in full-resolution pixels.
  RefineOptions refine = options_.relocalization.pose.refinement;
  if (result->status == TrackStatus::kTracking) refine.loss_scale_px = options_.tracking.refine_loss_scale_px;
  refine.loss_scale_px *= resolution_.full_per_work();
  const RefineResult refined = RefinePose(resolution_.full(), pixels, points, result->pose, refine);
  if (refined.ok) result->pose = refined.pose;
  result->times.refine_ms += MillisecondsSince(start);
}

bool Tracker::LightSwitchHeld(double timestamp) const {
  return timestamp - last_light_switch_timestamp_ < options_.tracking.light_switch_hold_s;
}

Track2D3D Tracker::DropDriftedTracks(const Track2D3D& inliers, const calib::Pose& pose) const {
  const double bound = options_.tracking.max_track_residual_scales * rms_gate_.Scale();
  Track2D3D kept;
  for (size_t i = 0; i < inliers.pixels.size(); ++i) {
    const Eigen::Vector2d pixel(inliers.pixels[i].x, inliers.pixels[i].y);
    if (ReprojectionError(resolution_.work(), pose, pixel, map_.points[inliers.points[i]].xyz) > bound) continue;
    kept.pixels.push_back(inliers.pixels[i]);
    kept.points.push_back(inliers.points[i]);
  }
  return kept;
}

void Tracker::Remember(const FrameResult& result, double timestamp, const Track2D3D& inliers) {
  if (has_pose_ && result.status == TrackStatus::kTracking) {
    velocity_ = RelativeMotion(last_pose_, result.pose);
    velocity_dt_ = timestamp - last_timestamp_;
    has_velocity_ = true;
  } else {
    has_velocity_ = false;
  }
  // Not a frame held to the gate's upper bound after a light step: its RMS (clipped, relit
  // frames fit at 1.1-1.4 px) raised the learnt gate to 2.2 px for the next 5 s, and drifted
  // poses passed it (docs/tracker.md, "Third round").
  if (result.status == TrackStatus::kTracking && result.align_zncc == 0 && !LightSwitchHeld(timestamp))
    rms_gate_.Observe(result.rms_px);
  if (result.align_zncc == 0) {
    last_feature_timestamp_ = timestamp;
    // Relocalised centres only when nothing better is known: a relocalization in a blurred frame,
    // on a few dozen inliers, was 29 mm off where the tracked frames before it were 3 mm off.
    if (result.status == TrackStatus::kTracking || feature_centres_.empty())
      feature_centres_.Add(timestamp, result.pose.Center());
  }
  last_pose_ = result.pose;
  last_timestamp_ = timestamp;
  has_pose_ = true;
  const TrackingOptions& opt = options_.tracking;
  last_inliers_ = SpreadTracks(DropDriftedTracks(inliers, result.pose), opt.max_flow_tracks, opt.flow_grid_cell_px, resolution_.work().Size());
}

void Tracker::NameRoom(FrameResult* result) const {
  const int room = map::RoomAt(map_, result->center);
  if (room >= 0) result->room = map_.rooms[static_cast<std::size_t>(room)];
}

FrameResult Tracker::Track(const cv::Mat& image, double timestamp) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMilliseconds();
  ++frames_tracked_;
  FrameResult result;
  const cv::Mat full_gray = image.empty() ? cv::Mat() : ToGray8(image);
  const calib::Camera& camera = resolution_.full();
  if (full_gray.empty() || full_gray.size() != camera.Size()) {
    std::ostringstream msg;
    msg << "frame is " << full_gray.cols << "x" << full_gray.rows << ", the tracking camera is "
        << camera.width << "x" << camera.height;
    result.reason = msg.str();
    Reset();
  } else {
    const cv::Mat gray = resolution_.Reduce(full_gray);
    const FramePose posed = options_.tracking.background ? FramePose{TrackWithoutWaiting(gray, timestamp, &result)}
                                                         : PoseInLine(gray, timestamp, &result);
    EndFrame(gray, timestamp, posed, &result);
  }
  result.times.total_ms = MillisecondsSince(start);
  result.times.cpu_ms += ThreadCpuMilliseconds() - cpu_start;  // with a prefetch's worker CPU
  return result;
}

Tracker::FramePose Tracker::PoseInLine(const cv::Mat& gray, double timestamp, FrameResult* result_out) {
  FrameResult& result = *result_out;
  const std::vector<cv::Mat> reference_pyramid = last_pyramid_;  // the last posed frame's (shared)
  bool tracked = false;
  std::string tracking_reason;
  std::optional<Features> features;
  Track2D3D inliers;
  const double after_last_pose_s = timestamp - last_timestamp_;
  if (has_pose_) {
    tracked = TrackWithPrior(gray, timestamp, &result, &features, &inliers);
    if (!tracked) {
      inliers = {};
      tracked = TrackWide(gray, timestamp, &result, &features, &inliers);
    }
    tracking_reason = result.reason;
  }
  if (tracked) {
    result.status = TrackStatus::kTracking;
    result.reason.clear();
    const double fresh_after_s = options_.tracking.fresh_features_after_s;
    if (fresh_after_s >= 0 && after_last_pose_s > fresh_after_s) PoseFromFreshFeatures(gray, &result, &features, &inliers);
  } else {
    const RelocalizationResult reloc =
        features ? relocalizer_->Relocalize(*features) : relocalizer_->Relocalize(gray);
    result.keypoints = reloc.keypoints;
    result.matches = reloc.matches;
    result.times.extract_ms += reloc.extract_ms;
    result.times.match_ms += reloc.match_ms;
    CopyStats(reloc.pose, &result);
    if (reloc.pose.ok) {
      result.status = TrackStatus::kRelocalized;
      result.pose = reloc.pose.pose;
      result.reason = tracking_reason;
      inliers = reloc.inliers;
      if (last_pyramid_.empty() || !has_pose_) last_pyramid_ = FlowPyramid(gray);
    } else {
      result.reason = (tracking_reason.empty() ? "" : tracking_reason + "; ") +
                      "relocalization failed: " + reloc.pose.reason;
      result.inliers = 0;
      if (has_pose_ && TrackByAlignment(reference_pyramid, gray, timestamp, &result)) {
        result.status = TrackStatus::kTracking;
        result.rms_px = 0;
        inliers = {};  // nothing to follow: the next frame starts from guided matching
      } else {
        result.status = TrackStatus::kLost;
        result.relocalization_failure = reloc.pose.failure;
      }
    }
  }
  // A relocalization on its own SIFT (no features were extracted before it) may hold weaker
  // keypoints than flow should follow (relocalization_keypoints_followed_).
  const bool followed_by_flow =
      result.status != TrackStatus::kRelocalized || features.has_value() || relocalization_keypoints_followed_;
  return {std::move(inliers), followed_by_flow};
}

void Tracker::EndFrame(const cv::Mat& gray, double timestamp, const FramePose& posed, FrameResult* result) {
  if (result->status == TrackStatus::kLost) {
    ForgetPrior();  // a relocalization pending on the worker is kept
    return;
  }
  RefineOnFullCamera(posed.inliers, result);
  Remember(*result, timestamp, posed.followed_by_flow ? posed.inliers : Track2D3D{});
  MaybePrefetch(gray, *result);
  result->center = result->pose.Center();
  result->smoothed_center = smoother_.Filter(result->center, timestamp);
  NameRoom(result);
}

}  // namespace arview::tracker
