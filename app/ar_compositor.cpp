#include "app/ar_compositor.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "app/character_bounds.h"
#include "app/view_hud.h"
#include "render/hud.h"
#include "render/projection.h"

namespace arview::app {

ArCompositor::ArCompositor(const calib::Camera& camera, std::vector<const anim::AnimatedCharacter*> characters,
                           const CompositorOptions& options)
    : camera_(camera), characters_(std::move(characters)), options_(options) {
  // Created here, before the pipeline's threads start: creating a context sets LP_NUM_THREADS
  // in the environment, which must not race with other threads.
  context_ = render::OffscreenContext::Create(options_.gl);
  renderer_ = std::make_unique<render::ArRenderer>(*context_, camera_, options_.ar);
  if (options_.room_light) renderer_->SetRoomLight(*options_.room_light);
  for (const anim::AnimatedCharacter* c : characters_) {
    renderer_->AddCharacter(c->character(), c->spec());
    heights_.push_back(RestHeight(c->character(), c->spec().up) * c->spec().scale * c->spec().anchor.scale);
  }
  description_ = context_->Description();
}

void ArCompositor::DrawHud(cv::Mat& frame, const FrameToCompose& input) const {
  std::vector<render::HudSphere> spheres;
  for (size_t i = 0; i < characters_.size() && i < input.animations.size(); ++i) {
    const AnimatedFrame& a = *input.animations[i];
    spheres.push_back(HudSphereFor(characters_[i]->spec(), a.key_weights, a.viewpoint, heights_[i]));
  }
  render::HudText text;
  if (!input.animations.empty()) {
    char line[96];
    std::snprintf(line, sizeof line, "frame %lld   idle weight %.2f", static_cast<long long>(input.frame->index),
                  input.animations.front()->idle_weight);
    text.status.push_back(line);
  }
  const calib::Camera& k = renderer_->pinhole();
  if (!options_.hmd) {
    render::DrawHud(frame, k, input.track->pose, spheres, text);
    return;
  }
  for (int eye = 0; eye < 2; ++eye) {
    cv::Mat half = frame(cv::Rect(eye * k.width, 0, k.width, k.height));
    render::DrawHud(half, k, render::OffsetEye(input.track->pose, (eye == 0 ? -0.5 : 0.5) * options_.ipd_m), spheres, text);
  }
}

void ArCompositor::BindToThread() { context_->MakeCurrent(); }

cv::Size ArCompositor::OutputSize() const {
  return {options_.hmd ? 2 * camera_.width : camera_.width, camera_.height};
}

cv::Mat ArCompositor::Compose(const FrameToCompose& input) {
  const bool localized = input.track->status != tracker::TrackStatus::kLost;
  outputs_.clear();
  output_ptrs_.clear();
  if (localized) {
    outputs_.reserve(input.animations.size());
    for (const AnimatedFrame* a : input.animations) {
      anim::FrameOutput out;
      out.weights = a->key_weights;
      out.model = a->model;
      out.skinning_matrices = a->skinning_matrices;
      out.skinning_dual_quats = a->skinning_dual_quats;
      outputs_.push_back(out);
    }
    for (const anim::FrameOutput& o : outputs_) output_ptrs_.push_back(&o);
  }
  if (localized || characters_.empty()) {
    const calib::Pose pose = localized ? input.track->pose : calib::Pose{};
    cv::Mat frame = options_.hmd ? renderer_->RenderSideBySide(input.frame->image, pose, output_ptrs_, options_.ipd_m)
                                 : renderer_->Render(input.frame->image, pose, output_ptrs_);
    if (options_.hud && localized && !characters_.empty()) DrawHud(frame, input);
    return frame;
  }
  // Lost: no pose to register the characters with, so the video is shown alone, undistorted
  // like the augmented frames (the renderer's maps: same K, pinhole output).
  cv::Mat frame = input.frame->image;
  if (frame.channels() == 1) cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
  if (camera_.HasDistortion()) {
    if (undistort_x_.empty()) {
      cv::initUndistortRectifyMap(camera_.K(), camera_.DistCoeffs(), cv::noArray(), camera_.K(), camera_.Size(), CV_16SC2,
                                  undistort_x_, undistort_y_);
    }
    cv::Mat undistorted;
    cv::remap(frame, undistorted, undistort_x_, undistort_y_, cv::INTER_LINEAR);
    frame = undistorted;
  }
  if (!options_.hmd) return frame.clone();
  cv::Mat both;
  cv::hconcat(frame, frame, both);
  return both;
}

}  // namespace arview::app
