#include "anim/animator.h"

#include <algorithm>
#include <cmath>

namespace arview::anim {

double DistanceWeight::At(double d) const {
  if (points.empty()) return 1;
  if (d <= points.front().first) return points.front().second;
  for (std::size_t i = 1; i < points.size(); ++i)
    if (d <= points[i].first) {
      const auto& [d0, w0] = points[i - 1];
      const auto& [d1, w1] = points[i];
      return d1 > d0 ? w0 + (w1 - w0) * (d - d0) / (d1 - d0) : w1;
    }
  return points.back().second;
}

FrameBuffers::FrameBuffers(const Skeleton& skeleton)
    : local(1, LocalPose::Rest(skeleton)),
      model(skeleton.size(), Eigen::Matrix4d::Identity()),
      skin(skeleton.size(), Eigen::Matrix4f::Identity()),
      skin_dq(skeleton.size(), DualQuatf()) {}

void FrameBuffers::Finish(const Skeleton& skeleton, AnimatorFrame& frame, const char* local_to_model,
                          const char* skinning) {
  MustRun(LocalToModelJob{&skeleton, &local[0], model}, local_to_model);
  MustRun(SkinningMatricesJob{&skeleton, model, skin, skin_dq}, skinning);
  frame.skinning_matrices = skin;
  frame.skinning_dual_quats = skin_dq;
  frame.model = model;
  frame.local = local;
  frame.morph_weights = local[0].morph;
}

Animator::Animator(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<Schedule> schedule, AnimatorOptions options,
                   std::shared_ptr<const ViewAdaptiveBlend> view)
    : skeleton_(std::move(skeleton)), schedule_(std::move(schedule)), options_(std::move(options)), view_(std::move(view)) {
  if (!skeleton_ || !schedule_ || schedule_->joint_count() != skeleton_->size())
    throw Error("animator: schedule and skeleton disagree");
  if (!(options_.hold_seconds >= 0) || !(options_.fade_seconds >= 0))
    throw Error("animator: hold and fade times must be non-negative");
  if (!options_.view_action.empty()) view_id_ = schedule_->FindByName(options_.view_action);
  for (const DistanceWeight& w : options_.distance_weights) {
    const int id = schedule_->FindByName(w.action);
    if (id < 0) throw Error("distance weight: no action named '" + w.action + "' in the schedule");
    for (std::size_t i = 0; i < w.points.size(); ++i)
      if (!std::isfinite(w.points[i].first) || !(w.points[i].second >= 0) || !std::isfinite(w.points[i].second) ||
          (i > 0 && !(w.points[i].first > w.points[i - 1].first)))
        throw Error("distance weight for '" + w.action + "': points need increasing distances and weights >= 0");
    weight_ids_.push_back(id);
  }
  for (const DistanceTrigger& t : options_.triggers) {
    if (!(t.near >= 0) || !(t.far > t.near) || !std::isfinite(t.far))
      throw Error("distance trigger '" + t.action.name + "': needs 0 <= near < far");
    if (!t.action.object || t.action.object->joint_count() != skeleton_->size())
      throw Error("distance trigger '" + t.action.name + "': its object does not fit the skeleton");
  }
  if (options_.gaze && options_.gaze->rig.valid()) gaze_.emplace(*skeleton_, options_.gaze->rig, options_.gaze->options);
  if (options_.face && !options_.face->valid()) options_.face.reset();
  armed_.assign(options_.triggers.size(), true);
  fired_ids_.reserve(16);
  buffers_ = FrameBuffers(*skeleton_);
}

void Animator::Track(double time, bool tracking) {
  if (view_id_ < 0) return;
  if (tracking) {
    if (lost_since_ && fading_out_) schedule_->FadeGain(view_id_, 1.0, time, options_.fade_seconds);
    lost_since_.reset();
    fading_out_ = false;
    return;
  }
  if (!lost_since_) lost_since_ = time;
  if (!fading_out_ && time - *lost_since_ >= options_.hold_seconds) {
    schedule_->FadeGain(view_id_, 0.0, time, options_.fade_seconds);
    fading_out_ = true;
  }
}

void Animator::RemoveEndedActions(double time) {
  // Triggered and played actions that have ended leave the schedule (their slot is reused).
  for (std::size_t i = 0; i < fired_ids_.size();) {
    const Action* a = schedule_->Find(fired_ids_[i]);
    if (!a || (!a->keep_rendering && time > a->start + a->object->Duration())) {
      schedule_->Remove(fired_ids_[i]);
      fired_ids_[i] = fired_ids_.back();
      fired_ids_.pop_back();
    } else {
      ++i;
    }
  }
}

int Animator::Play(Action action) {
  const int id = schedule_->Add(std::move(action));
  fired_ids_.push_back(id);
  return id;
}

void Animator::HoldGazeOnViewer(double from, double until) {
  if (gaze_) gaze_->HoldOnViewer(from, until);
}

void Animator::Distance(double time, double distance) {
  frame_.triggered = 0;
  RemoveEndedActions(time);
  if (!(distance >= 0) || !std::isfinite(distance)) return;  // unknown: nothing distance-driven changes
  for (std::size_t i = 0; i < weight_ids_.size(); ++i)
    schedule_->SetLiveWeight(weight_ids_[i], options_.distance_weights[i].At(distance));
  for (std::size_t i = 0; i < options_.triggers.size(); ++i) {
    const DistanceTrigger& t = options_.triggers[i];
    if (armed_[i] && distance <= t.near) {
      Action a = t.action;
      a.start += time;
      fired_ids_.push_back(schedule_->Add(std::move(a)));
      armed_[i] = false;
      ++frame_.triggered;
    } else if (!armed_[i] && distance > t.far) {
      armed_[i] = true;
    }
  }
}

bool Animator::SetMorphWeight(int target, float weight) {
  std::vector<float>& weights = buffers_.local[0].morph;
  if (target < 0 || target >= static_cast<int>(weights.size()) || !std::isfinite(weight)) return false;
  weights[target] = weight;
  return true;
}

void Animator::Look(double time, const Eigen::Vector3d* viewer) {
  if (viewer) viewer_ = *viewer;
  // The head where the schedule (the look-at chain) put it, then the eyes from there; Finish's
  // pass over every joint comes after.
  gaze_->PoseEyes(*skeleton_, time, viewer_, buffers_.local[0], buffers_.model);
  frame_.gaze = gaze_->frame();
  frame_.gaze.eyes_on_viewer = frame_.gaze.eyes_on_viewer && viewer != nullptr;
}

const AnimatorFrame& Animator::Update(double time, const FrameInputs& inputs, const FaceTrack* face) {
  if (!std::isfinite(time)) time = last_time_.value_or(0.0);
  if (last_time_ && time < *last_time_) {  // a restart (replay from the beginning)
    lost_since_.reset();
    fading_out_ = false;
    if (view_id_ >= 0) schedule_->FadeGain(view_id_, 1.0, time, 0.0);
  }
  last_time_ = time;
  Track(time, inputs.tracking);
  if (inputs.tracking && inputs.viewpoint.squaredNorm() > 0 && inputs.viewpoint.allFinite())
    viewpoint_ = inputs.viewpoint.normalized();
  Distance(time, inputs.distance);
  inputs_ = inputs;
  inputs_.viewpoint = viewpoint_;  // held while lost
  if (!schedule_->Sample(time, inputs_, buffers_.local[0])) throw Error("animator: an action's object refused its inputs");
  const FaceTrack silent;
  if (options_.face) frame_.face = ApplySpeechToFace(*options_.face, face ? *face : silent, buffers_.local[0]);
  if (gaze_) {
    // Talking switches gaze to Eyes Alive's talking statistics, and back to the scene's mode after.
    const bool talking = frame_.face.talking > 0;
    const GazeMode mode = talking ? GazeMode::kTalking : options_.gaze->options.mode;
    if (gaze_->behaviour().mode() != mode) gaze_->SetMode(mode);
    Look(time, inputs.tracking && inputs.viewer.allFinite() ? &inputs.viewer : nullptr);
    if (options_.face) OverrideLidsWithBlink(*options_.face, frame_.gaze.blink_closure, buffers_.local[0]);
  }
  buffers_.Finish(*skeleton_, frame_, "animator: local to model", "animator: skinning matrices");
  frame_.key_weights = view_ ? view_->weights() : std::span<const double>();
  frame_.view_gain = view_id_ >= 0 ? schedule_->Gain(view_id_, time) : 0.0;
  frame_.viewpoint = viewpoint_;
  frame_.converged = schedule_->last_converged() && (!view_ || view_->converged());
  return frame_;
}

}  // namespace arview::anim
