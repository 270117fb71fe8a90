#pragma once
// The augmented frame: the camera image as background, the placed characters over it with
// depth, a soft contact shadow under each, antialiased with 4x MSAA (llvmpipe offers 4).
//
// Cost: only the screen rectangle that can contain the characters and their shadows (bounded
// from the posed joints and each joint's skin radius) is cleared, drawn, resolved and read
// back, as premultiplied RGBA; it is blended over the video frame on the CPU. The video never
// goes through OpenGL, and multisampling costs in proportion to the character's size on screen.
//
// Lens distortion: the background is undistorted with maps precomputed once
// (cv::initUndistortRectifyMap, same K) and the characters are rendered with the matching
// pinhole camera, so the output is the undistorted view (docs/render.md has the measured cost).

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <span>
#include <vector>

#include "anim/scene.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "render/character_renderer.h"
#include "render/offscreen.h"
#include "render/projection.h"

namespace arview::render {

enum class Antialiasing {
  // 4x multisampling (llvmpipe's maximum). A cheap post pass (a 3x3 box or Gaussian filter on
  // the silhouette's edges) was tried and measured farther from the 4x MSAA image than no
  // antialiasing at all, so it is not offered.
  kMsaa,
  kNone,
};
// "msaa" | "none"; throws RenderError otherwise.
Antialiasing ParseAntialiasing(const std::string& name);

struct ArOptions {
  Antialiasing antialiasing = Antialiasing::kMsaa;
  ClipRange clip{0.02, 200.0};
  anim::SkinningMethod skinning = anim::SkinningMethod::kDualQuaternion;
  bool shadow = true;
  bool cull_back_faces = true;  // see CharacterDraw
  float shadow_strength = 0.55f;
  cv::Scalar empty_background{128, 128, 128};  // BGR, when no camera image is given
  bool full_frame = false;  // draw and read the whole frame (for checking the bounds)
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
  struct ShadowEllipse {
    Eigen::Vector3d center, axis_u, axis_v;
  };
  cv::Mat PrepareBackground(const cv::Mat& background);
  // Draws the characters seen from `eye` and blends them over `frame` (in place).
  void Compose(cv::Mat& frame, const calib::Pose& eye, std::span<const anim::FrameOutput* const> frames);
  bool Shadow(const Placed& placed, const anim::FrameOutput& frame, ShadowEllipse* ellipse) const;
  // The screen rectangle that contains everything drawn (empty when nothing is in view).
  cv::Rect ScreenBounds(const calib::Pose& eye, std::span<const anim::FrameOutput* const> frames) const;

  OffscreenContext* context_;
  calib::Camera camera_, pinhole_;
  ArOptions options_;
  RenderTarget target_;
  cv::Mat undistort_map1_, undistort_map2_;
  ContactShadow shadow_;
  std::vector<Placed> characters_;
  bool used_linear_fallback_ = false;
};

}  // namespace arview::render
