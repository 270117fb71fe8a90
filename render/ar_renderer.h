#pragma once
// The augmented frame: the camera image as background, the placed characters over it with
// depth, a soft contact shadow under each, antialiased with 4x MSAA (llvmpipe offers 4).
//
// Cost: only the screen rectangle that can contain the characters and their shadows (bounded
// from the posed joints and each joint's skin radius) is cleared, drawn, resolved and read
// back, as premultiplied RGBA, in a target about the rectangle's size (RegionTarget: llvmpipe
// clears a whole target faster than a scissored part); it is blended over the video frame on the CPU. The video never
// goes through OpenGL, and multisampling costs in proportion to the character's size on screen.
//
// Lens distortion: the background is undistorted with maps precomputed once
// (cv::initUndistortRectifyMap, same K) and the characters are rendered with the matching
// pinhole camera, so the output is the undistorted view (docs/render.md has the measured cost).

#include <opencv2/core.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <span>
#include <vector>

#include "anim/animator.h"
#include "anim/character.h"
#include "anim/placement.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "render/character_renderer.h"
#include "render/offscreen.h"
#include "render/projection.h"
#include "room/room_light.h"
#include "render/scene_depth.h"
#include "render/shadow_capsules.h"

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

// How the character's layer comes back from OpenGL (render/gl_objects.h, PixelReadback).
enum class Readback {
  kAuto,         // a pixel buffer on a GPU, glReadPixels on llvmpipe
  kDirect,       // glReadPixels after the cast shadow is drawn: on llvmpipe its rasteriser
                 // threads draw the layer while the render thread darkens the video
  kPixelBuffer,  // the copy into a pixel buffer is started before the cast shadow, mapped after:
                 // on a GPU the copy runs meanwhile; on llvmpipe it would wait for the raster first
};

struct ArOptions {
  Antialiasing antialiasing = Antialiasing::kMsaa;
  ClipRange clip{0.02, 200.0};
  anim::SkinningMethod skinning = anim::SkinningMethod::kDualQuaternion;
  bool shadow = true;
  bool cull_back_faces = true;  // see CharacterDraw
  float shadow_strength = 0.55f;
  cv::Scalar empty_background{128, 128, 128};  // BGR, when no camera image is given
  bool full_frame = false;  // draw and read the whole frame (for checking the bounds)
  // A mesh's weighted morph targets holding at most this many vertex deltas together are added
  // on the CPU, more in the vertex shader (CharacterRenderer::set_cpu_morph_max_deltas; 0: always
  // the shader).
  int cpu_morph_max_deltas = CharacterRenderer::kDefaultCpuMorphMaxDeltas;
  Readback readback = Readback::kAuto;
  // The room's light (SetRoomLight) for kShUnshadowed / kShShadowed; kShShadowed ray casts
  // each character's PRT transfer in AddCharacter (prt_seconds() says how long it took).
  LightingMode lighting = LightingMode::kFixed;
  bool cast_shadow = true;      // from the room light's dominant direction, when there is a room light
  bool occlusion = true;        // the room light's occluder triangles in the depth buffer first
  float cast_shadow_softness = 0.03f;  // blur radius, share of the character's bounding diameter
  float cast_shadow_max_strength = 0.8f;
  double exposure_smoothing = 0.5;     // room::ExposureFollower's share per update (every 4th frame)
  PrtOptions prt;
  // Where AddCharacter keeps and finds the PRT transfer (render/prt_cache.h); empty: computed
  // every time. The app passes DefaultPrtCacheFolder().
  std::filesystem::path prt_cache_folder;
};

class ArRenderer {
 public:
  // `camera` is the calibrated camera of the video (with its distortion, if any).
  ArRenderer(OffscreenContext& context, const calib::Camera& camera, const ArOptions& options = {});
  ArRenderer(const ArRenderer&) = delete;
  ArRenderer& operator=(const ArRenderer&) = delete;

  // The character must outlive the renderer; its placement is copied. Returns its index for Render's frames.
  int AddCharacter(const anim::Character& character, const anim::Placement& placement);
  // Where character `index` (AddCharacter's) stands from the next Render on.
  void MoveCharacter(int index, const anim::Placement& placement);

  // One augmented frame, BGR at the camera's size. `background`: the camera image (8-bit BGR or
  // grey, the camera's size) or empty; `pose`: the camera, world → camera; `frames[i]`: the
  // animation output (anim::Animator::Update, anim::PlacedCharacter::Update) of character i.
  cv::Mat Render(const cv::Mat& background, const calib::Pose& pose,
                 std::span<const anim::AnimatorFrame* const> frames);
  // HMD mode: the two eyes ±ipd/2 along the camera's x axis, each over the same video frame,
  // side by side (left eye on the left): 2W x H.
  cv::Mat RenderSideBySide(const cv::Mat& background, const calib::Pose& pose,
                           std::span<const anim::AnimatorFrame* const> frames, double ipd_m);

  // Draws `frames` from `pose` once into a scratch frame and leaves no trace in what later frames
  // look like (the exposure followed is untouched): the shaders compile and llvmpipe builds its
  // pipeline state now (about 1 s, and more on a loaded machine), not at the first live frame.
  void WarmUp(const calib::Pose& pose, std::span<const anim::AnimatorFrame* const> frames);

  // The room's light: SH and dominant light for the SH lighting modes and the cast shadow, the
  // keyframe thumbnails the live exposure is followed against, the occluder triangles.
  void SetRoomLight(const room::RoomLight& light);
  // Replaces the depth-only occluders (map frame, 3 corners a triangle); empty: none.
  void SetOccluders(const std::vector<Eigen::Vector3f>& triangles);
  // The SH light of the last frame (the room light times the followed exposure gain).
  const room::ShRgb& current_sh() const { return current_sh_; }
  Eigen::Vector3d exposure_gain() const { return follower_ ? follower_->gain() : Eigen::Vector3d::Ones(); }
  // Total PRT precomputation time of the characters added so far, seconds.
  double prt_seconds() const { return prt_seconds_; }
  // How many of the characters' transfers were read from the PRT cache, and why a cache file
  // was not used or written (empty when all went well).
  int prt_from_cache() const { return prt_from_cache_; }
  const std::string& prt_cache_note() const { return prt_cache_note_; }

  const calib::Camera& pinhole() const { return pinhole_; }
  const ArOptions& options() const { return options_; }
  // Whether the layer is read through a pixel buffer (options().readback, resolved for the context).
  bool reads_through_pixel_buffer() const { return pixel_buffer_readback_; }
  // Whether the last Render had to skin a character linearly because its joints scale.
  bool used_linear_fallback() const { return used_linear_fallback_; }

 private:
  struct Placed {
    const anim::Character* character;
    anim::Placement placement;
    std::unique_ptr<CharacterRenderer> renderer;
    std::vector<ShadowCapsule> capsules;  // the cast shadow's occluder, bind pose
    bool casts = false;                   // this frame's cast shadow (UpdateCastShadows):
    LightView light_view;                 // its light view and floor quad,
    cv::Mat coverage;                     // its soft coverage (kCastShadowTexels a side)
  };
  struct ShadowEllipse {
    Eigen::Vector3d center, axis_u, axis_v;
  };
  cv::Mat PrepareBackground(const cv::Mat& background);
  // Draws the characters seen from `eye` and blends them over `frame` (in place), after
  // UpdateCastShadows of the same frames.
  void Compose(cv::Mat& frame, const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames);
  // The premultiplied BGRA layer (OpenGL's rows: row 0 at the bottom) over `rect` of `frame`.
  static void BlendPremultiplied(const cv::Mat& bottom_up_layer, const cv::Rect& rect, cv::Mat& frame);
  // Draws the characters' layer (occluders, contact shadows, characters) into `rect` of the
  // region target, to be read back.
  void DrawLayer(const cv::Rect& rect, const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames,
                 double farthest);
  bool Shadow(const Placed& placed, const anim::AnimatorFrame& frame, ShadowEllipse* ellipse) const;
  // Each character's cast shadow for this frame (kept in Placed for Compose, which darkens the
  // camera image with it); throws when `frames` is not one per character.
  void UpdateCastShadows(std::span<const anim::AnimatorFrame* const> frames);
  // The cast shadow's light view and soft coverage for this frame (false: no cast shadow).
  bool CastShadowView(const Placed& placed, const anim::AnimatorFrame& frame, LightView* view, cv::Mat* coverage) const;
  float CastShadowStrength(const Placed& placed) const;
  void FollowExposure(const cv::Mat& background, const calib::Pose& pose);
  // The screen rectangle that contains everything drawn (empty when nothing is in view), and
  // the farthest distance along the view axis of what is drawn (bounding boxes; infinity when
  // not known): occluders wholly behind it are not drawn.
  cv::Rect ScreenBounds(const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames, double* farthest) const;

  OffscreenContext* context_;
  calib::Camera camera_, pinhole_;
  ArOptions options_;
  RegionTarget target_;
  bool pixel_buffer_readback_ = false;
  cv::Mat undistort_map1_, undistort_map2_;
  ContactShadow shadow_;
  std::vector<Placed> characters_;
  bool used_linear_fallback_ = false;
  bool has_room_light_ = false;
  room::RoomLight room_light_;
  room::ShRgb current_sh_{};
  std::unique_ptr<room::ExposureFollower> follower_;
  std::unique_ptr<DepthProxy> occluders_;
  std::vector<Eigen::Vector3f> occluder_triangles_;  // the same, for the cast shadow on the CPU
  double prt_seconds_ = 0;
  int prt_from_cache_ = 0;
  std::string prt_cache_note_;
  static constexpr int kExposureEvery = 4;
  long frames_since_exposure_ = 0;
};

}  // namespace arview::render
