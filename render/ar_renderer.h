#pragma once
// The augmented frame: the camera image as background, the placed characters over it with
// depth, a soft contact shadow under each, antialiased with 4x MSAA (llvmpipe offers 4).
//
// Lens distortion: the background is undistorted with maps precomputed once
// (cv::initUndistortRectifyMap, same K) and the characters are rendered with the matching
// pinhole camera, so the output is the undistorted view (docs/render.md has the measured cost).

#include <opencv2/core.hpp>

#include <memory>
#include <span>
#include <vector>

#include "anim/scene.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "render/character_renderer.h"
#include "render/offscreen.h"
#include "render/projection.h"

namespace arview::render {

struct ArOptions {
  int samples = 4;  // MSAA; 0 or 1 disables
  ClipRange clip{0.02, 200.0};
  anim::SkinningMethod skinning = anim::SkinningMethod::kDualQuaternion;
  bool shadow = true;
  float shadow_strength = 0.55f;
  cv::Scalar empty_background{128, 128, 128};  // BGR, when no camera image is given
};

class ArRenderer {
 public:
  // `camera` is the calibrated camera of the video (with its distortion, if any).
  ArRenderer(OffscreenContext& context, const calib::Camera& camera, const ArOptions& options = {});
  ArRenderer(const ArRenderer&) = delete;
  ArRenderer& operator=(const ArRenderer&) = delete;

  // The character and spec must outlive the renderer. Returns its index for Render's frames.
  int AddCharacter(const anim::Character& character, const anim::CharacterSpec& spec);

  // One augmented frame, BGR at the camera's size. `background`: the camera image (8-bit BGR or
  // grey, the camera's size) or empty; `pose`: the camera, world → camera; `frames[i]`: the
  // animation output (anim::AnimatedCharacter::Update) of character i.
  cv::Mat Render(const cv::Mat& background, const calib::Pose& pose,
                 std::span<const anim::FrameOutput* const> frames);
  // HMD mode: the two eyes ±ipd/2 along the camera's x axis, each over the same video frame,
  // side by side (left eye on the left): 2W x H.
  cv::Mat RenderSideBySide(const cv::Mat& background, const calib::Pose& pose,
                           std::span<const anim::FrameOutput* const> frames, double ipd_m);

  const calib::Camera& pinhole() const { return pinhole_; }
  const ArOptions& options() const { return options_; }
  // Whether the last Render had to skin a character linearly because its joints scale.
  bool used_linear_fallback() const { return used_linear_fallback_; }

 private:
  struct Placed {
    const anim::Character* character;
    const anim::CharacterSpec* spec;
    std::unique_ptr<CharacterRenderer> renderer;
  };
  void PrepareBackground(const cv::Mat& background);
  void Draw(const calib::Pose& eye, std::span<const anim::FrameOutput* const> frames);
  void DrawShadow(const Placed& placed, const anim::FrameOutput& frame, const Eigen::Matrix4d& projection,
                  const Eigen::Matrix4d& view);

  OffscreenContext* context_;
  calib::Camera camera_, pinhole_;
  ArOptions options_;
  RenderTarget target_;
  cv::Mat undistort_map1_, undistort_map2_, undistorted_;
  GlName background_program_, background_vao_, background_texture_;
  bool has_background_ = false;
  ContactShadow shadow_;
  std::vector<Placed> characters_;
  bool used_linear_fallback_ = false;
};

}  // namespace arview::render
