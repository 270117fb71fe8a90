#include "app/ar_compositor.h"

namespace arview::app {

ArCompositor::ArCompositor(const calib::Camera& camera, std::vector<const anim::AnimatedCharacter*> characters,
                           const CompositorOptions& options)
    : camera_(camera), characters_(std::move(characters)), options_(options) {
  // Created here, before the pipeline's threads start: creating a context sets LP_NUM_THREADS
  // in the environment, which must not race with other threads.
  context_ = render::OffscreenContext::Create(options_.gl);
  renderer_ = std::make_unique<render::ArRenderer>(*context_, camera_, options_.ar);
  for (const anim::AnimatedCharacter* c : characters_) renderer_->AddCharacter(c->character(), c->spec());
  description_ = context_->Description();
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
  // Lost: no pose to register the characters with, so the video is shown alone (through the
  // renderer all the same, so that a distorted camera's frames stay undistorted like the others).
  const calib::Pose pose = localized ? input.track->pose : calib::Pose{};
  if (options_.hmd) return renderer_->RenderSideBySide(input.frame->image, pose, output_ptrs_, options_.ipd_m);
  return renderer_->Render(input.frame->image, pose, output_ptrs_);
}

}  // namespace arview::app
