#include "anim/gaze.h"

#include "anim/seeded_draw.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace arview::anim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;
constexpr double kFrame = 1.0 / 30;  // Eyes Alive gives fixation lengths in frames of its 30 Hz video
constexpr double kMinFixationSeconds = kFrame;  // a fixation lasts at least one of those frames
constexpr double kMinBlinkGapSeconds = 0.3;     // between two blinks' starts (a blink takes 0.25 s)
// The lids: the upper lid turns down this far to meet the lower lid, which rises a little.
constexpr double kUpperLidCloseDeg = 45, kLowerLidRiseDeg = 8;

// Eyes Alive (Lee, Badler & Badler 2002): the direction histogram is the same for both modes;
// the magnitude caps, mutual-gaze shares and fixation lengths (frames at 30 Hz) are per mode.
constexpr std::array<double, 8> kDirections = {15.54, 6.46, 17.69, 7.44, 16.80, 7.89, 20.38, 7.79};

const SaccadeStatistics kTalking{kDirections, 27.5, 41, 93.9 * kFrame, 94.9 * kFrame, 27.8 * kFrame, 24.0 * kFrame};
const SaccadeStatistics kListening{kDirections, 22.7, 75, 237.5 * kFrame, 47.1 * kFrame, 13.0 * kFrame, 7.1 * kFrame};

double SmoothStep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// A standard normal draw (Box-Muller on seeded_draw's uniform: the same on every platform).
double Normal(std::mt19937_64& rng) {
  const double u1 = 1.0 - Uniform(rng);  // (0, 1]
  const double u2 = Uniform(rng);
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
}

// The mean of a Gaussian (mean, sd) truncated below at `low`: the fixation lengths as drawn.
double TruncatedMean(double mean, double sd, double low) {
  const double a = (low - mean) / sd;
  const double pdf = std::exp(-0.5 * a * a) / std::sqrt(2 * kPi);
  const double survival = 0.5 * std::erfc(a / std::sqrt(2.0));
  return mean + sd * pdf / survival;
}

// The mean of the capped magnitude law: min(−6.9·ln(P/15.7), cap), P uniform in (0, 15].
double MeanMagnitude(double cap) {
  const double least = -6.9 * std::log(15.0 / 15.7);
  return least + 6.9 * (1 - 15.7 / 15.0 * std::exp(-cap / 6.9));
}

// The chance that each next fixation is on the viewer, such that the share of *time* in mutual
// gaze is the mode's: f = p·m / (p·m + (1 − p)·a + S(p)), m and a the mean fixation lengths as
// drawn, S the mean saccade time per fixation (none between two mutual fixations; a look away
// or back moves by the mean magnitude, one away to another about √2 of it). Bisection: the
// share grows with p.
double MutualChance(const SaccadeStatistics& stats) {
  const double f = stats.mutual_percent / 100;
  const double m = TruncatedMean(stats.mutual_mean_s, stats.mutual_sd_s, kMinFixationSeconds);
  const double a = TruncatedMean(stats.away_mean_s, stats.away_sd_s, kMinFixationSeconds);
  const double look = SaccadeDurationSeconds(MeanMagnitude(stats.max_magnitude_deg));
  const double shift = SaccadeDurationSeconds(std::sqrt(2.0) * MeanMagnitude(stats.max_magnitude_deg));
  auto share = [&](double p) { return p * m / (p * m + (1 - p) * a + 2 * p * (1 - p) * look + (1 - p) * (1 - p) * shift); };
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) (share(0.5 * (lo + hi)) < f ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// The unit gaze direction of an offset (yaw toward x, pitch up; degrees) from straight ahead +Z.
Eigen::Vector3d Direction(const Eigen::Vector2d& deg) {
  const double yaw = deg.x() * kDeg, pitch = deg.y() * kDeg;
  return {std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch)};
}

double AngleDeg(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector3d u = Direction(a), v = Direction(b);
  return std::atan2(u.cross(v).norm(), u.dot(v)) / kDeg;
}

// Model-space rest transforms (allocates: construction only).
std::vector<Eigen::Matrix4d> RestModel(const Skeleton& skeleton) {
  std::vector<Eigen::Matrix4d> model(skeleton.size());
  for (int j = 0; j < skeleton.size(); ++j) {
    const Eigen::Matrix4d local = skeleton.rest[j].ToMatrix();
    model[j] = skeleton.parents[j] < 0 ? Eigen::Matrix4d(skeleton.root_parent * local) : Eigen::Matrix4d(model[skeleton.parents[j]] * local);
  }
  return model;
}

Eigen::Matrix3d Rotation(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) r.col(c).normalize();
  return r;
}

}  // namespace

const SaccadeStatistics& EyesAliveStatistics(GazeMode mode) { return mode == GazeMode::kTalking ? kTalking : kListening; }

double DefaultBlinkRate(GazeMode mode) { return mode == GazeMode::kRest ? 17 : 26; }

void GazeOptions::Check() const {
  if (!(blink_rate_per_min >= 0 && blink_rate_per_min <= 100))
    throw Error("gaze: blink rate " + std::to_string(blink_rate_per_min) + " per minute is outside 0..100 (0: the mode's)");
  auto angle_ok = [](double a) { return a > 0 && a <= 60; };
  if (!angle_ok(range.sideways_deg) || !angle_ok(range.up_deg) || !angle_ok(range.down_deg))
    throw Error("gaze: the eye range (sideways " + std::to_string(range.sideways_deg) + ", up " + std::to_string(range.up_deg) +
                ", down " + std::to_string(range.down_deg) + " degrees) must lie in (0, 60]");
}

double BlinkClosure(double s) {
  if (!(s >= 0) || s > kBlinkSeconds) return 0;
  if (s < 0.05) return SmoothStep(s / 0.05);
  return 1 - SmoothStep((s - 0.05) / (kBlinkSeconds - 0.05));
}

// ---------------------------------------------------------------------------------------------

GazeBehaviour::GazeBehaviour(const GazeOptions& options)
    : options_(options), mode_(options.mode), stats_(&EyesAliveStatistics(options.mode)) {
  options_.Check();
  SetMode(options_.mode);
}

void GazeBehaviour::SetMode(GazeMode mode) {
  mode_ = mode;
  stats_ = &EyesAliveStatistics(mode);
  blink_rate_ = options_.blink_rate_per_min > 0 ? options_.blink_rate_per_min : DefaultBlinkRate(mode);
  p_mutual_ = MutualChance(*stats_);
}

void GazeBehaviour::Restart(double origin) {
  saccade_rng_.seed(options_.seed);
  blink_rng_.seed(options_.seed ^ 0x9e3779b97f4a7c15ull);
  from_ = to_ = Eigen::Vector2d::Zero();
  saccade_start_ = saccade_end_ = origin;
  target_mutual_ = true;
  fixation_end_ = origin + DrawFixation(true);
  last_blink_ = -1e9;
  blinks_started_ = 0;
  next_blink_ = origin;
  ScheduleNextBlink();
  if (log_) *log_ = GazeLog{};
  now_ = origin;
}

double GazeBehaviour::DrawFixation(bool mutual) {
  const double mean = mutual ? stats_->mutual_mean_s : stats_->away_mean_s;
  const double sd = mutual ? stats_->mutual_sd_s : stats_->away_sd_s;
  for (;;) {  // truncated below at one frame (rejection: the accepted draws are Gaussian above it)
    const double s = mean + sd * Normal(saccade_rng_);
    if (s >= kMinFixationSeconds) return s;
  }
}

Eigen::Vector2d GazeBehaviour::DrawLookAway(double* magnitude_deg) {
  const int bin = Draw(saccade_rng_, stats_->direction_percent);
  const double p = 15.0 * (1.0 - Uniform(saccade_rng_));  // P in (0, 15]
  const double magnitude = std::min(-6.9 * std::log(p / 15.7), stats_->max_magnitude_deg);
  *magnitude_deg = magnitude;
  const double direction = 45.0 * bin * kDeg;
  return {magnitude * std::cos(direction), magnitude * std::sin(direction)};
}

void GazeBehaviour::ScheduleNextBlink() {
  // Intervals: a refractory gap, then exponential (a Poisson process above the gap), mean 60/rate.
  const double mean = 60.0 / blink_rate_;
  next_blink_ += kMinBlinkGapSeconds - (mean - kMinBlinkGapSeconds) * std::log(1.0 - Uniform(blink_rng_));
}

void GazeBehaviour::BlinkAt(double t, bool with_saccade) {
  last_blink_ = t;
  ++blinks_started_;
  if (log_) log_->blinks.push_back({t, with_saccade});
}

void GazeBehaviour::NextFixation() {
  const double t0 = fixation_end_;
  if (log_ && target_mutual_) log_->mutual_seconds += t0 - saccade_end_;
  const bool next_mutual = Uniform(saccade_rng_) * 100 < 100 * p_mutual_;
  if (next_mutual && target_mutual_) {  // the eyes stay on the viewer: a new fixation, no saccade
    from_ = to_;
    saccade_start_ = saccade_end_ = t0;
    fixation_end_ = t0 + DrawFixation(true);
    return;
  }
  double magnitude = 0;
  const Eigen::Vector2d target = next_mutual ? Eigen::Vector2d::Zero() : DrawLookAway(&magnitude);
  const double amplitude = AngleDeg(to_, target);
  const double duration = SaccadeDurationSeconds(amplitude);
  if (log_) log_->saccades.push_back({t0, duration, amplitude, magnitude, target_mutual_, next_mutual});
  // A large gaze shift brings the next blink forward to it (people blink with most of them);
  // the blink schedule's count is kept: the scheduled blink is taken, not an extra one.
  if (magnitude >= kBlinkShiftDeg && t0 - last_blink_ >= kMinBlinkGapSeconds && next_blink_ - t0 <= 2 * 60.0 / blink_rate_) {
    BlinkAt(t0, true);
    ScheduleNextBlink();
  }
  from_ = to_;
  to_ = target;
  saccade_start_ = t0;
  saccade_end_ = t0 + duration;
  target_mutual_ = next_mutual;
  fixation_end_ = saccade_end_ + DrawFixation(next_mutual);
}

void GazeBehaviour::Advance(double t) {
  if (!std::isfinite(t)) t = std::max(now_, 0.0);
  t = std::max(t, 0.0);
  if (now_ < 0 || t < now_) Restart(0);
  // A jump of more than an hour (a single render at --time 1e9) starts the walk afresh there
  // rather than walking every event since 0: about one a second.
  if (t - now_ > kLongestWalkSeconds) Restart(t);
  for (;;) {
    if (next_blink_ <= fixation_end_) {
      if (next_blink_ > t) break;
      if (next_blink_ - last_blink_ >= kMinBlinkGapSeconds) BlinkAt(next_blink_, false);
      ScheduleNextBlink();
    } else {
      if (fixation_end_ > t) break;
      NextFixation();
    }
  }
  now_ = t;
  if (t < saccade_end_) {
    const double u = (t - saccade_start_) / (saccade_end_ - saccade_start_);
    offset_ = from_ + (to_ - from_) * SmoothStep(u);
  } else {
    offset_ = to_;
  }
  mutual_ = target_mutual_ && t >= saccade_end_;
  closure_ = BlinkClosure(t - last_blink_);
}

// ---------------------------------------------------------------------------------------------

namespace {

int FindJoint(const Skeleton& skeleton, const char* name) {
  // Exact, or after a namespace prefix ("mixamorig:LeftEye").
  const std::string wanted = name;
  for (int j = 0; j < skeleton.size(); ++j) {
    const std::string& n = skeleton.names[j];
    if (n == wanted || (n.size() > wanted.size() && n.compare(n.size() - wanted.size(), wanted.size(), wanted) == 0 &&
                        n[n.size() - wanted.size() - 1] == ':'))
      return j;
  }
  return -1;
}

// Joint j's local rotation replaced, its translation kept.
void SetRotation(LocalPose& local, int j, const Eigen::Quaterniond& q) {
  local.rigid[j] = DualQuatd::FromRotationTranslation(q, local.rigid[j].Translation());
}

}  // namespace

GazeRig FindGazeRig(const Skeleton& skeleton, const Eigen::Vector3d& forward, const Eigen::Vector3d& up) {
  GazeRig rig;
  rig.forward = forward;
  rig.up = up;
  const char* names[2][3] = {{"LeftEye", "LeftUpperLid", "LeftLowerLid"}, {"RightEye", "RightUpperLid", "RightLowerLid"}};
  for (int s = 0; s < 2; ++s) {
    rig.eyes[s].eye = FindJoint(skeleton, names[s][0]);
    rig.eyes[s].upper_lid = FindJoint(skeleton, names[s][1]);
    rig.eyes[s].lower_lid = FindJoint(skeleton, names[s][2]);
  }
  return rig;
}

Gaze::Gaze(const Skeleton& skeleton, const GazeRig& rig, const GazeOptions& options)
    : rig_(rig), options_(options), behaviour_(options) {
  if (!rig_.valid()) throw Error("gaze: the skeleton has no LeftEye and RightEye joints");
  const std::vector<Eigen::Matrix4d> rest = RestModel(skeleton);
  const Eigen::Vector3d up_model = rig_.up.normalized();
  const Eigen::Vector3d forward_model = (rig_.forward - rig_.forward.dot(up_model) * up_model).normalized();
  for (int s = 0; s < 2; ++s) {
    const GazeRig::Side& side = rig_.eyes[s];
    Eye& e = eyes_[s];
    auto check = [&](int j) {
      if (j >= skeleton.size() || (j >= 0 && skeleton.parents[j] != skeleton.parents[side.eye]) || (j >= 0 && skeleton.parents[j] < 0))
        throw Error("gaze: " + skeleton.names[j < skeleton.size() ? j : side.eye] + ": an eye or lid joint must share the eye's parent (the head)");
    };
    check(side.eye);
    check(side.upper_lid);
    check(side.lower_lid);
    e.joint = side.eye;
    e.parent = skeleton.parents[side.eye];
    e.upper = side.upper_lid;
    e.lower = side.lower_lid;
    e.rest = skeleton.rest[e.joint].rotation;
    if (e.upper >= 0) e.upper_rest = skeleton.rest[e.upper].rotation;
    if (e.lower >= 0) e.lower_rest = skeleton.rest[e.lower].rotation;
    const Eigen::Matrix3d parent = Rotation(rest[e.parent]);
    e.forward_parent = (parent.transpose() * forward_model).normalized();
    e.up_parent = (parent.transpose() * up_model).normalized();
    e.side_parent = e.up_parent.cross(e.forward_parent).normalized();
  }
  const int heads[2] = {eyes_[0].parent, eyes_[1].parent};
  head_chain_ = JointChain(skeleton, heads);
}

void Gaze::PoseEyes(const Skeleton& skeleton, double t, const Eigen::Vector3d& viewer_model, LocalPose& local,
                    std::span<Eigen::Matrix4d> model) {
  MustRun(JointsToModelJob{&skeleton, &local, head_chain_, model}, "gaze: the head's chain to model space");
  Apply(t, viewer_model, model, local);
}

Eigen::Vector2d Gaze::YawPitch(const Eye& e, const Eigen::Vector3d& d) {
  const double x = d.dot(e.side_parent), y = d.dot(e.up_parent), z = d.dot(e.forward_parent);
  return {std::atan2(x, z) / kDeg, std::atan2(y, std::hypot(x, z)) / kDeg};
}

Eigen::Quaterniond Gaze::Turn(const Eye& e, double yaw_deg, double pitch_deg) {
  return Eigen::AngleAxisd(yaw_deg * kDeg, e.up_parent) * Eigen::AngleAxisd(-pitch_deg * kDeg, e.side_parent);
}

void Gaze::Apply(double t, const Eigen::Vector3d& viewer_model, std::span<const Eigen::Matrix4d> model, LocalPose& local) {
  const long blinks_before = behaviour_.blinks_started();
  const double time_before = last_time_;
  behaviour_.Advance(t);
  last_time_ = t;
  const bool viewer_known = viewer_model.allFinite();
  const double closure = behaviour_.blink_closure();
  const bool held_on_viewer = t >= hold_on_viewer_from_ && t < hold_on_viewer_until_;
  const Eigen::Vector2d offset = held_on_viewer ? Eigen::Vector2d::Zero() : behaviour_.offset_deg();
  const EyeRange& range = options_.range;
  bool in_range = viewer_known;
  for (const Eye& e : eyes_) {
    const Eigen::Matrix4d& parent = model[e.parent];
    Eigen::Vector2d toward = Eigen::Vector2d::Zero();
    if (viewer_known) {
      const Eigen::Vector3d centre = (parent * local.rigid[e.joint].Translation().homogeneous()).head<3>();
      toward = YawPitch(e, Rotation(parent).transpose() * (viewer_model - centre));
      in_range = in_range && std::abs(toward.x()) <= range.sideways_deg && toward.y() <= range.up_deg && toward.y() >= -range.down_deg;
    }
    const Eigen::Vector2d target = toward + offset;
    const double yaw = std::clamp(target.x(), -range.sideways_deg, range.sideways_deg);
    const double pitch = std::clamp(target.y(), -range.down_deg, range.up_deg);
    SetRotation(local, e.joint, Turn(e, yaw, pitch) * e.rest);
    // The upper lid follows the eye's pitch (all the way down, part of the way up), the lower
    // lid a little of it downward; a blink closes both over that.
    const double upper = (1 - closure) * pitch * (pitch < 0 ? 1.0 : 0.6) - closure * kUpperLidCloseDeg;
    const double lower = (1 - closure) * 0.3 * std::min(pitch, 0.0) + closure * kLowerLidRiseDeg;
    if (e.upper >= 0) SetRotation(local, e.upper, Turn(e, 0, upper) * e.upper_rest);
    if (e.lower >= 0) SetRotation(local, e.lower, Turn(e, 0, lower) * e.lower_rest);
  }
  frame_.active = true;
  frame_.eyes_on_viewer = in_range && (held_on_viewer || behaviour_.mutual());
  frame_.blinking = behaviour_.blinking();
  frame_.blink_closure = static_cast<float>(closure);
  frame_.talking_mode = behaviour_.mode() == GazeMode::kTalking;
  // Restarted (time went back, or a jump of over an hour): the blinks since the restart.
  const long now = behaviour_.blinks_started();
  frame_.blinks_begun = static_cast<int>(t < time_before || now < blinks_before ? now : now - blinks_before);
}

}  // namespace arview::anim
