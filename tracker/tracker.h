#pragma once
// Per-frame camera pose against a map. With a prior (the previous frames were localised) the
// pose is predicted with a constant-velocity model, last frame's inliers are followed with
// pyramidal Lucas-Kanade, guided matches are added when the flow tracks thin out, and a short
// RANSAC + refinement verifies the pose. Without a prior, or when tracking fails, the frame is
// relocalised globally (tracker/relocalizer.h). A pose is reported only when verified.

#include <opencv2/core.hpp>

#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/enum_table.h"
#include "base/error.h"
#include "map/descriptor_index.h"
#include "map/map.h"
#include "tracker/centre_fitter.h"
#include "tracker/clipped_windows.h"
#include "tracker/hidden_points.h"
#include "tracker/moving_tracks.h"
#include "tracker/one_euro.h"
#include "tracker/relocalizer.h"
#include "tracker/research_trigger.h"
#include "tracker/residual_gate.h"
#include "tracker/rotation_aligner.h"
#include "tracker/tracking_worker.h"
#include "tracker/working_resolution.h"

namespace arview::tracker {

struct TrackerError : Error {
  using Error::Error;
};

enum class TrackStatus { kTracking, kRelocalized, kLost };
constexpr auto EnumNames(TrackStatus) {
  return EnumTable<TrackStatus, 3>{{{TrackStatus::kTracking, "tracking"},
                                    {TrackStatus::kRelocalized, "relocalized"},
                                    {TrackStatus::kLost, "lost"}}};
}

// Every pixel quantity below is in working-resolution pixels (TrackerOptions::working_long_side).
struct TrackingOptions {
  // Side of LK's window: its cost grows with the area, and 11x11 was faster and more exact than
  // 21x21 (docs/tracker.md, "Why the tracking options are what they are").
  int lk_window_px = 11;
  // LK pyramid levels above the frame, each doubling the motion followed: 5 follow ~160 px, as
  // 21x21 with 4 levels did (docs/tracker.md, "Why the tracking options are what they are").
  int lk_pyramid_levels = 5;
  int lk_max_iterations = 20;  // LK's iterations per pyramid level
  // At most this many inliers are followed into the next frame, spread over the image: LK and
  // refinement time grow with the count, and a few hundred well-spread points pin the pose.
  int max_flow_tracks = 300;
  // An inlier is followed on only within this many residual scales (ResidualGate::Scale()): LK
  // drifts, old tracks fit worse (docs/tracker.md, "Why the tracking options are what they are").
  double max_track_residual_scales = 2.0;
  int flow_grid_cell_px = 40;  // cell of the grid the followed inliers are spread over
  // Guided matching (SIFT on the frame, matched only against map points projected within a
  // radius) runs when fewer flow tracks than this survive.
  int replenish_below = 150;
  // Keyframes whose observations guided matching projects: those seeing most of the flow tracks
  // (covisibility), or without tracks the nearest looking the same way.
  int guided_keyframes = 4;
  // Guided matching's radius around a projection by the pose refined on the flow tracks.
  double guided_radius_px = 10;
  // The wider radius when only the motion prediction projects (too few flow tracks); also the
  // farthest a prefetched keypoint may end from where the current pose projects its point.
  double guided_radius_predicted_px = 25;
  double guided_ratio = 0.85;  // ratio test of guided matching
  // SIFT keypoints for guided matching: many, since matching them costs little and the tracked
  // pose needs points spread over the whole view.
  int guided_max_features = 2000;
  // SIFT contrast threshold of guided matching and the wide search: near a projection OpenCV's
  // default suffices; 0.02 did worse (docs/tracker.md, "Why the tracking options are what they are").
  double guided_contrast_threshold = 0.04;
  // Guided SIFT is extracted ahead on a worker thread below this many flow tracks, for a camera
  // dropping frames; 0, off: less exact (docs/tracker.md, "Why the tracking options are what they are").
  int prefetch_below = 0;
  // Frames after which features extracted ahead are used (sooner when the flow tracks fall below
  // replenish_below); the frame that uses them waits for them, so results do not depend on timing.
  // Not with `background`, which never waits.
  int prefetch_lag_frames = 6;
  // A live source: nothing on the tracking thread waits for SIFT or a relocalization. Guided
  // matching's SIFT is extracted ahead (below prefetch_below flow tracks) and used by the first
  // frame that finds it done; meanwhile, and when it is late, frames are posed on flow alone.
  // A relocalization (the first frame, a loss) runs on the worker too: frames meanwhile are lost
  // (or posed by image alignment), and the first frame that finds it done follows its inliers by
  // LK from the relocalised frame. Poses then depend on timing; false: every step in line
  // (docs/tracker.md, "The tracking worker").
  bool background = false;
  // The pose is first refined from the constant-velocity prediction; it is kept when its inliers
  // are at least this fraction of the correspondences, else a short RANSAC runs.
  double prior_min_inlier_ratio = 0.5;
  int ransac_max_iterations = 50;  // the inlier ratio is high when tracking
  // RANSAC's inlier threshold when tracking and in the wide search (relocalization has its own):
  // the correspondences come from flow and guided matching on a moving, often blurred camera.
  double ransac_threshold_px = 4.0;
  // Where the Cauchy loss of a tracked frame's refinement bends (relocalization has its own,
  // RelocalizerOptions::pose.refinement): flow and guided matches on a moving camera.
  double refine_loss_scale_px = 2.0;
  // A RANSAC pose turned further than this from the prediction is refused (a P3P solution
  // mirrored on a nearly planar patch explains the points almost as well as the true one).
  double max_rotation_from_prediction_deg = 20;
  int min_inliers = 30;            // below this, fall back to relocalization
  // The wide search, for jumps flow cannot follow, matches within this fraction of the image's
  // longest side; 0: off (docs/tracker.md, "Why the tracking options are what they are").
  double wide_radius_fraction = 0.3;
  // The most a wide-search pose may turn from the last pose or the prediction, whichever is nearer:
  // the jumps seen turned over 20 deg (docs/tracker.md, "Why the tracking options are what they are").
  double wide_max_rotation_deg = 30;
  double wide_ratio = 0.8;           // ratio test of the wide search
  int wide_ransac_iterations = 500;  // RANSAC iterations of the wide search
  // The largest accepted inlier RMS follows the residual scale of recent tracked frames
  // (tracker/residual_gate.h): drifted tracks and wrong matches fit worse, and are relocalised.
  ResidualGateOptions rms_gate;
  // The constant-velocity motion is scaled by the time since the last frame over the time it was
  // measured on, at most this many times (a dropped frame doubles the motion).
  double max_prediction_ratio = 4;
  // Whip-pans, which no feature survives, are posed by image alignment for this long after the
  // last pose from features; 0: off (docs/tracker.md, "Why the tracking options are what they are").
  double align_max_seconds = 0.5;
  double align_max_from_prediction_deg = 15;  // the most an aligned rotation may turn
  RotationAlignerOptions align;               // tracker/rotation_aligner.h
  // Frames far apart (a sub-sampled clip, a set of photos tracked as a sequence): a tracked frame
  // that comes more than fresh_features_after_s after the last posed one has its SIFT (guided
  // matching's, extracted when the flow did not need it) matched against the whole map and posed
  // as relocalization poses a frame (ratio test against every map point, RANSAC at
  // relocalization's threshold, refinement on its inliers); that pose replaces the tracked one
  // when it has at least min_inliers inliers and turns at most fresh_max_rotation_deg from it,
  // and its inliers are what the flow follows next. Optical flow is made for a camera's frame
  // rate: over motions of hundreds of pixels it drifts from frame to frame and pulls the pose
  // with it (phone-fox's odd frames, 2-16 video frames apart: 0.0040-0.0050 -> 0.0018-0.0020
  // units median over three default maps; docs/tracker.md, "Fresh features on frames far
  // apart"). One SIFT extraction and one global matching a frame. The default, 0.25 s (under 4
  // frames a second), leaves a camera's video to the flow alone: the room's lap at 30 fps is
  // tracked exactly as without it. 0: every tracked frame; negative: never. Not applied with
  // `background` (a live session).
  double fresh_features_after_s = 0.25;
  double fresh_max_rotation_deg = 3;
  // The frame LK follows into is scaled to the previous flow image's mean grey when the two
  // differ by more than this share (a light change; tracker/brightness_match.h).
  double flow_brightness_tolerance = 0.05;
  // A light switched: a frame whose brightness scaling stepped by `light_switch_ev` or more from
  // the last one's (a lamp: 2 EV, 0.6 EV when it comes back on frames an exposure raised and
  // clips; an auto-exposure's own steps are 1/3 EV). For
  // `light_switch_hold_s` after it a tracked pose is held to the RMS gate's upper bound
  // (rms_gate.max_px), not the gate learnt on steady frames, and those frames do not teach the
  // gate (docs/tracker.md, "Third round"). Off by default (0 s): held 0.5 s on the lights
  // sequence, no frame was relocalised, but the relit step frame passed 68 mm off at 1.46 px and
  // recall at 2 cm/2 deg fell from 99.7% to 93.9%.
  double light_switch_ev = 0.5;
  double light_switch_hold_s = 0;
  // Flow tracks and guided matches on things that move in front of the map, rejected before the
  // pose (tracker/moving_tracks.h; docs/tracker.md, "People walking through").
  MovingTrackOptions moving;
  // Points whose tracks someone walking through took away, followed back when the flow thins
  // out, before guided matching (tracker/hidden_points.h; docs/tracker.md, "People walking through").
  HiddenPointOptions hidden;
  // Tracks dropped by the patch test counted as expected back before the flow re-searches
  // (tracker/research_trigger.h; docs/tracker.md, "Fourth round").
  ResearchTriggerOptions research;
  // Flow tracks on windows the frame clips white, dropped before the pose
  // (tracker/clipped_windows.h; docs/tracker.md, "Fourth round").
  ClippedWindowOptions clipped;

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};
// TrackingOptions::prefetch_below of a live session (TrackingOptions::background), where guided
// matching's SIFT is only ever extracted ahead (docs/tracker.md, "The tracking worker").
inline constexpr int kBackgroundPrefetchBelow = 200;

// FLANN's default 64 leaves per query, halved: on templeRing and the synthetic room the same
// frames localise with the same accuracy, and global matching is ~1.5x faster.
inline map::IndexParams DefaultIndexParams() {
  map::IndexParams p;
  p.checks = 32;
  return p;
}

struct TrackerOptions {
  RelocalizerOptions relocalization;
  TrackingOptions tracking;
  OneEuroOptions smoothing;
  map::IndexParams index = DefaultIndexParams();
  int min_map_points = 30;  // a map with fewer points is refused at construction
  // Longest side of the image every per-frame step works on (0: the camera's full size); the
  // frames stay at the map camera's resolution (tracker/working_resolution.h).
  int working_long_side = 960;
  // The final refinement on the full camera model (pixels mapped back to full resolution).
  bool refine_on_full_camera = true;
  // Where the map's descriptor index is kept between sessions (map::DescriptorIndex::Cached);
  // empty: built every time. The same index either way.
  std::filesystem::path index_cache_folder;

  // Throws OptionError naming the first bad field, of this struct or a member's (the Tracker
  // calls it at construction; `arview track` first, with its flags' names).
  void Check(const OptionNames& names = {}) const;
};

struct StageTimes {
  double flow_ms = 0;
  double extract_ms = 0;  // on the worker thread (CPU) for features extracted ahead
  double match_ms = 0;  // global (FLANN) or guided
  double ransac_ms = 0;
  double refine_ms = 0;
  double total_ms = 0;  // wall time of Track()
  double cpu_ms = 0;    // CPU time of the calling thread during Track()
};

struct FrameResult {
  TrackStatus status = TrackStatus::kLost;
  calib::Pose pose;  // raw refined pose (world → camera); meaningful unless lost
  Eigen::Vector3d center = Eigen::Vector3d::Zero();           // C = −Rᵀt
  Eigen::Vector3d smoothed_center = Eigen::Vector3d::Zero();  // One Euro filtered C
  int inliers = 0;
  double rms_px = 0;       // inlier RMS, working pixels
  double rms_gate_px = 0;  // the largest RMS a tracked pose could have had (tracking only)
  int flow_tracks = 0;     // LK tracks that survived into this frame
  // Why the flow's tracks thin out (docs/tracker.md, "Third round"): the last frame's tracks it
  // started from, those LK lost (or that left the picture) of them whose points the prediction
  // put in view, and those the pose then left out as outliers.
  int flow_followed_from = 0;
  int flow_lost_in_view = 0;
  int flow_outliers = 0;
  double flow_motion_px = 0;  // their median move from the last frame, pixels of the working frame
  int guided_matches = 0;  // added by guided matching
  int moving_rejected = 0; // flow tracks and guided matches rejected as on something moving
  int moving_by_patch = 0;   // of those, flow tracks whose patch changed
  int moving_by_motion = 0;  // of those, flow tracks that moved against the prediction
  int clipped_rejected = 0;  // flow tracks on windows the frame clips white (TrackingOptions::clipped)
  int recovered_tracks = 0;  // hidden points followed back from the last frame that saw them
  int prefetched_matches = 0;  // of those, matched in a frame extracted ahead and followed by LK
  int wide_matches = 0;    // matches of the wide search (tracking after a motion flow lost)
  // > 0: the tracked pose was replaced by the pose of the frame's own SIFT matched globally, on
  // this many inliers (TrackingOptions::fresh_features_after_s).
  int fresh_inliers = 0;
  // > 0: the pose's rotation came from image alignment (TrackingOptions::align_max_seconds), with
  // this correlation, its centre from the recent path; no correspondence supports it.
  double align_zncc = 0;
  int keypoints = 0;       // SIFT keypoints extracted (0 when SIFT did not run)
  int matches = 0;         // global matches (relocalization)
  std::string reason;      // why the frame is lost, or why tracking fell back
  // Lost because the relocalization running on the worker (TrackingOptions::background) has not
  // finished: the frame was not tried against the map.
  bool awaiting_relocalization = false;
  int relocalized_frames_ago = 0;  // relocalized from the worker's result: on this many frames before
  // Lost: what relocalization's pose solver failed at (kNone: it did not run, e.g. a frame of
  // the wrong size); tracker/loss_diagnosis.h turns it and the frame's numbers into a cause.
  PoseFailure relocalization_failure = PoseFailure::kNone;
  // A venue's map (map::Map::rooms): the room the frame was localized in, its nearest keyframe's
  // (map::RoomAt); empty when lost or when the map has no rooms.
  std::string room;
  StageTimes times;
};

// Threads: every method is called from one thread at a time (the pipeline's `arview-track`, the
// main thread of `arview track`). With TrackingOptions::background or prefetch_below a
// TrackingWorker's thread works beside it, on its own copies, relocalizer and SIFT; the two share
// only the map and its index, which both only read (tracker/tracking_worker.h).
class Tracker {
 public:
  // Checks the options (OptionError naming the field, as "tracker.<path>"), validates the map and
  // builds its descriptor index. `map` must outlive the tracker. Throws TrackerError when the map
  // has too few points or inconsistent descriptors.
  Tracker(const map::Map& map, const TrackerOptions& options = {});
  // The same for frames from `camera`, which need not be the map's: the map's points are in
  // world metres and its SIFT descriptors do not depend on the camera that saw them, so frames
  // of another size, focal length and distortion are projected with their own camera; the
  // working resolution is taken from it (`--working-size` applies to its size).
  Tracker(const map::Map& map, const calib::Camera& camera, const TrackerOptions& options = {});
  ~Tracker();

  // image: 8-bit grey or BGR at the tracking camera's resolution (the map camera's unless
  // another was given); timestamp in seconds.
  FrameResult Track(const cv::Mat& image, double timestamp);
  // Forgets the prior: the next frame is relocalised.
  void Reset();
  // Runs each per-frame step once on a blank working-size frame (SIFT, the flow pyramid, one
  // descriptor query) and forgets it. A process's first SIFT extraction pays one-time costs
  // (OpenCV's lazy set-up, the allocator's first touch of its buffers: ~25 ms at 360x640 here)
  // that would otherwise land on the session's first frame, which is always a relocalization.
  // Sessions call it once after construction, before frames arrive; the result is unchanged.
  void WarmUp();
  const TrackerOptions& options() const { return options_; }
  // One line when the descriptor index's cache could not be used (map::DescriptorIndex::Cached);
  // empty when it was, or without a cache folder.
  const std::string& index_note() const { return index_note_; }
  // The camera every per-frame step uses (the map camera scaled to the working resolution).
  const calib::Camera& working_camera() const { return resolution_.work(); }

 private:
  struct Prefetch;
  struct Recovery;
  struct GuidedCandidate {  // a map point where a pose projects it, for guided matching
    static constexpr std::uint32_t kEveryDescriptor = 0xffffffffu;
    Eigen::Vector2d pixel;
    std::uint32_t point;
    // The one descriptor row to compare with (the wide search: the nearest keyframe's view of
    // the point), or kEveryDescriptor: the nearest of all of the point's.
    std::uint32_t descriptor = kEveryDescriptor;
  };
  // `features` matched to the candidates within `radius` pixels, with Lowe's `ratio`; one match
  // per map point, the closest (guided_matching.cpp).
  static std::vector<MapMatch> MatchGuided(const Features& features, const std::vector<GuidedCandidate>& candidates,
                                           const map::Map& map, double radius, double ratio, const cv::Size& size);
  // `features` receives the frame's SIFT when guided matching extracted it, so that a fallback
  // to relocalization does not extract it again.
  bool TrackWithPrior(const cv::Mat& gray, double timestamp, FrameResult* result,
                      std::optional<Features>* features, Track2D3D* inliers);
  // After TrackWithPrior failed: the wide search around the prediction (wide_radius_fraction).
  bool TrackWide(const cv::Mat& gray, double timestamp, FrameResult* result,
                 std::optional<Features>* features, Track2D3D* inliers);
  // A tracked frame posed again from its own SIFT matched globally (fresh_features_after_s):
  // replaces result->pose and *inliers when that pose agrees with the tracked one (then
  // result->fresh_inliers > 0).
  void PoseFromFreshFeatures(const cv::Mat& gray, FrameResult* result, std::optional<Features>* features,
                             Track2D3D* inliers) const;
  // After every feature-based step failed: the rotation from `reference_pyramid` (the last posed
  // frame's) to `gray` by image alignment, the centre predicted.
  bool TrackByAlignment(const std::vector<cv::Mat>& reference_pyramid, const cv::Mat& gray, double timestamp,
                        FrameResult* result) const;
  calib::Pose Predict(double timestamp) const;
  void RefineOnFullCamera(const Track2D3D& inliers, FrameResult* result) const;
  // The pose solver's options for a tracked frame (flow and guided matching, the wide search):
  // relocalization's, with tracking's RANSAC threshold, inlier count and RMS gate, and a seed
  // that changes with frame_counter_.
  AbsolutePoseOptions TrackedPoseOptions(int ransac_iterations) const;
  void Remember(const FrameResult& result, double timestamp, const Track2D3D& inliers);
  // The room of a localized frame (FrameResult::room) from its centre.
  void NameRoom(FrameResult* result) const;
  // Starts extracting this frame's guided features on a worker thread when its flow tracks are
  // thinning (TrackingOptions::prefetch_below).
  void MaybePrefetch(const cv::Mat& gray, const FrameResult& result);
  // What a frame's pose rests on: its correspondences, and whether the flow follows them into
  // the next frame.
  struct FramePose {
    Track2D3D inliers;
    bool followed_by_flow = true;
  };
  // Every step in line (TrackingOptions::background off): flow, guided matching, the wide search,
  // relocalization, image alignment, as each before it fails.
  FramePose PoseInLine(const cv::Mat& gray, double timestamp, FrameResult* result);
  // The end of every frame, in line or with the worker: a lost frame forgets the prior; a posed
  // one is refined on the full camera, remembered, smoothed and given its room.
  void EndFrame(const cv::Mat& gray, double timestamp, const FramePose& posed, FrameResult* result);
  // TrackingOptions::background: one frame, with no step that waits for SIFT or relocalization.
  // Returns the correspondences the pose rests on (empty when lost or aligned).
  Track2D3D TrackWithoutWaiting(const cv::Mat& gray, double timestamp, FrameResult* result);
  // Starts relocalising `gray` on the worker, unless a relocalization is already pending.
  void StartRecovery(const cv::Mat& gray);
  // The worker's relocalization, its inliers followed by LK into `gray`, posed; false when it
  // failed (result->reason says why).
  bool FinishRecovery(const cv::Mat& gray, FrameResult* result, Track2D3D* inliers);
  // Forgets the prior, keeping a pending relocalization.
  void ForgetPrior();
  // The map points of the keyframes covisible with `tracked_points` (without any, the nearest to
  // `pose`) that `pose` projects into the working image and that no step of this frame gathered
  // yet (they are stamped now): what guided matching matches keypoints against.
  std::vector<GuidedCandidate> GuidedCandidates(const calib::Pose& pose, const std::vector<std::uint32_t>& tracked_points);
  // A frame's image pyramid for LK, with the tracking options' window and levels.
  std::vector<cv::Mat> FlowPyramid(const cv::Mat& gray) const;
  // Pyramidal LK with the tracking options, `to` holding the starting guesses; the status per point.
  // `errors`, when given, gets LK's patch error per point.
  std::vector<unsigned char> FollowByLk(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                                        const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
                                        std::vector<float>* errors = nullptr) const;
  // A frame's 2D-3D correspondences: pixels (working camera), the map points' positions and ids.
  struct Correspondences {
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> points;
    std::vector<std::uint32_t> point_ids;
  };
  // Map points seen at `from` in one frame followed by LK into another, started at `guesses`:
  // those the flow kept that end inside the image and, given `keep(i, pixel)`, that it accepts,
  // appended to `out`. The number appended.
  int FollowIntoFrame(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                      const std::vector<cv::Point2f>& from, const std::vector<std::uint32_t>& point_ids,
                      std::vector<cv::Point2f> guesses, Correspondences* out,
                      const std::function<bool(std::size_t, const Eigen::Vector2d&)>& keep = {},
                      std::vector<float>* appended_errors = nullptr) const;
  // The flow tracks c[0, n) judged by the moving-track filter against where `predicted` puts
  // them: the rejected ones removed from `c` (the rest keep their order); the verdict.
  MovingTrackVerdict DropMovingTracks(const std::vector<Eigen::Vector2d>& predicted, const std::vector<float>& lk_errors,
                                      Correspondences* c, FrameResult* result);
  // The last frame's tracks that did not survive into this one although the prediction puts their
  // points in view (`in_view`, per track), kept as hidden points with the last frame's pyramid.
  void HideLostTracks(const std::vector<bool>& in_view);
  // Hidden points followed by LK from the frame that last saw them into `pyramid`, started where
  // `projecting` puts them, and appended to `c` when they end within HiddenPointOptions::radius_px
  // of it with a patch error within the moving-track filter's bound over `flow_lk_errors`; the
  // number appended.
  int RecoverHiddenPoints(const std::vector<cv::Mat>& pyramid, const calib::Pose& projecting,
                          const std::vector<float>& flow_lk_errors, Correspondences* c);
  // The correspondences c[from, end) whose LK window in `gray` is mostly clipped white, removed.
  void DropClippedTracks(const cv::Mat& gray, std::size_t from, Correspondences* c, FrameResult* result) const;
  // Correspondences c[from, end) that lie where the verdict rejected tracks, removed.
  void DropNearMoving(const MovingTrackVerdict& verdict, std::size_t from, Correspondences* c, FrameResult* result) const;
  // The pose from a prior: refined from it, and when that explains fewer than
  // prior_min_inlier_ratio of the correspondences, RANSAC without it (`prior_dropped`). The
  // solver's statistics of each attempt go into `result`.
  struct PriorPose {
    AbsolutePoseResult pose;
    bool prior_dropped = false;
  };
  PriorPose PoseFromPrior(const Correspondences& c, AbsolutePoseOptions options, FrameResult* result) const;
  // The prefetched frame's keypoints matched to the map and followed by LK into `pyramid`,
  // appended to the frame's correspondences; the number added.
  int UsePrefetch(const std::vector<cv::Mat>& pyramid, const calib::Pose& projecting, FrameResult* result,
                  Correspondences* correspondences);
  // The inliers whose reprojection error under `pose` (working camera) is within
  // max_track_residual_scales residual scales.
  // Within light_switch_hold_s of the last light switch (TrackingOptions::light_switch_ev).
  bool LightSwitchHeld(double timestamp) const;
  Track2D3D DropDriftedTracks(const Track2D3D& inliers, const calib::Pose& pose) const;
  std::vector<int> NearestKeyframes(const calib::Pose& pose) const;
  std::vector<int> CovisibleKeyframes(const std::vector<std::uint32_t>& points) const;

  const map::Map& map_;
  TrackerOptions options_;
  WorkingResolution resolution_;
  ResidualGate rms_gate_;
  map::DescriptorIndex index_;
  std::string index_note_;
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<SiftExtractor> guided_extractor_;
  // Whether the inliers of a relocalization on its own SIFT are followed by flow into the next
  // frame: only when that SIFT keeps no weaker keypoints than guided matching's. Flow follows a
  // keypoint's image patch, so the keypoint's localization error stays with the track for as long
  // as it lives; a weak keypoint (COLMAP's contrast threshold) is placed less exactly. Otherwise
  // the next frame starts from guided matching around the relocalised pose.
  bool relocalization_keypoints_followed_ = true;
  std::unique_ptr<Prefetch> prefetch_;                 // an extraction ahead, pending or done
  std::unique_ptr<Recovery> recovery_;                 // a relocalization on the worker, pending or done
  std::int64_t frames_tracked_ = 0;                    // Track() calls, for the prefetch's lag
  OneEuroFilter smoother_;

  // The prior.
  bool has_pose_ = false;
  bool has_velocity_ = false;
  calib::Pose last_pose_;
  calib::Pose velocity_;  // last_pose ∘ previous⁻¹
  double last_timestamp_ = 0;
  double last_feature_timestamp_ = 0;  // of the last frame posed from correspondences
  CentreFitter feature_centres_;       // their recent centres
  double velocity_dt_ = 0;  // the time velocity_ spans
  std::vector<cv::Mat> last_pyramid_;
  double last_light_switch_timestamp_ = -std::numeric_limits<double>::infinity();  // the last light switch's
  double last_light_gain_ = 1;  // what the last frame was scaled by for LK (tracker/brightness_match.h)
  Track2D3D last_inliers_;
  std::vector<std::vector<std::uint32_t>> point_keyframes_;  // per map point: keyframes seeing it
  std::vector<std::uint32_t> point_stamp_;  // per map point: frame number it was last gathered
  std::uint32_t frame_counter_ = 0;
  MovingTrackFilter moving_filter_;
  HiddenPoints hidden_;
  ResearchTrigger research_trigger_;
  // Background work (TrackingOptions::background, prefetch_below): its own relocalizer and SIFT,
  // so that no object here but the map and the index is touched by two threads
  // (tracker/tracking_worker.h). Last: destroyed first, so that a running job finishes while
  // the map and the index it reads still exist.
  std::unique_ptr<TrackingWorker> worker_;
};
}  // namespace arview::tracker
