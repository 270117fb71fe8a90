#pragma once
// The render stage of the pipeline on render::ArRenderer: the GL context is created with the
// compositor and bound to the render thread (BindToThread); the characters are drawn where the tracker says the camera is, and
// lost frames show the video alone.

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/pipeline/ar_pipeline.h"
#include "app/pipeline/recent_rate.h"
#include "app/pipeline/room_hud.h"
#include "render/ar_renderer.h"
#include "render/hmd.h"
#include "render/offscreen.h"

namespace arview::app {

// The HUD's lines for a character's dialogue: what was heard (with its confidence), the machine
// chosen last, the dominant emotion and the face's expression with its weight.
std::vector<std::string> DialogueHudLines(const CharacterDialogue& dialogue);

struct CompositorOptions {
  render::OffscreenOptions gl;
  render::ArOptions ar;
  bool hmd = false;   // side by side, one half per eye (render/hmd.h)
  // With hmd: the headset's panel, lens and pre-distortion; without, the halves are the camera's
  // views side by side (2W x H), undistorted.
  std::optional<render::HmdProfile> hmd_profile;
  // With hmd: the character rendered once per eye, ±ipd/2 apart; otherwise once, the same in
  // both eyes (biocular), as the video is (one camera: no per-eye view of the room).
  bool stereo_character = false;
  double ipd_m = 0.064;
  std::optional<room::RoomLight> room_light;  // SH light, exposure thumbnails, occluders
  bool hud = false;   // the overlay (render/hud.h): view sphere, weights, tracking status, frame rate

  // Throws OptionError naming the first bad field (base/option_check.h): a
  // stereo character without hmd, a negative ipd.
  void Check(const OptionNames& names = {}) const;
};

class ArCompositor : public FrameCompositor {
 public:
  // The characters must outlive the compositor. `context`: one made already (on this thread) with
  // options.gl; null: made here.
  ArCompositor(const calib::Camera& camera, std::vector<const anim::PlacedCharacter*> characters,
               const CompositorOptions& options, std::unique_ptr<render::OffscreenContext> context = nullptr);
  ~ArCompositor() override;
  // Draws the characters once, in their rest pose, from in front of the first, on the calling
  // thread (the context made current there and released again): the shaders' compilation and
  // llvmpipe's first draw, otherwise paid by the first live frame (1-3 s). Returns the seconds.
  double WarmUp();
  // Where character `index` stands from the next frame on; the character (constructor's) is
  // moved by the caller (anim::PlacedCharacter::SetPlacement). On the render thread.
  void MoveCharacter(size_t index, const anim::Placement& placement);
  void BindToThread() override;
  void UnbindFromThread() override;
  cv::Mat Compose(const FrameToCompose& input) override;
  // The HUD (CompositorOptions::hud), drawn on the sink's thread.
  std::function<void(cv::Mat&)> DeferredOverlay(const FrameToCompose& input) override;
  // The GL context's description.
  std::string Description() const { return description_; }
  const render::RendererInfo& Renderer() const { return context_->info(); }
  // What loading the characters is worth telling the user (the PRT transfer's time and its
  // cache), for the command to print as `note:` lines.
  const std::vector<std::string>& LoadNotes() const { return load_notes_; }
  cv::Size OutputSize() const;
  // The output's size for these options, before a compositor exists (to open the sink first).
  static cv::Size OutputSizeFor(const calib::Camera& camera, const CompositorOptions& options);
  // Shows or hides the HUD from another thread (the window's 'h' key): from the next frame on.
  void ToggleHud() { hud_visible_ = !hud_visible_; }

 private:
  // Draws the HUD of one frame on a camera-sized view whose eye sits `eye_offset_m` along the
  // camera's x axis; empty when the HUD is hidden.
  using HudDraw = std::function<void(cv::Mat& view, double eye_offset_m)>;
  HudDraw MakeHud(const FrameToCompose& input);
  // The two eyes' views of a frame (the same picture unless stereo_character), then the panel.
  cv::Mat ComposeForHmd(const FrameToCompose& input, bool localized);
  // The video alone, undistorted like the augmented frames: a lost frame.
  cv::Mat VideoAlone(const FrameToCompose& input);
  // The overlay's status lines: the frame, the tracking status, the output rate, the idle weight
  // (the room's lines are added by MakeHud).
  std::vector<std::string> HudStatus(const FrameToCompose& input) const;

  calib::Camera camera_;
  std::vector<const anim::PlacedCharacter*> characters_;
  CompositorOptions options_;
  std::unique_ptr<render::OffscreenContext> context_;
  std::unique_ptr<render::ArRenderer> renderer_;
  std::vector<const anim::AnimatorFrame*> output_ptrs_;
  std::string description_;
  std::vector<std::string> load_notes_;
  std::vector<double> heights_;  // characters' rest heights in map units, for the overlay
  cv::Mat undistort_x_, undistort_y_;  // for lost frames of a distorted camera
  RecentRate composed_{std::chrono::seconds(1)};  // the overlay's frame rate (wall clock)
  std::atomic<bool> hud_visible_;  // starts as options_.hud
  RoomHud room_hud_;               // a venue's room and its changes, kept while the HUD is hidden
  std::optional<render::HmdPresenter> presenter_;  // hmd with a profile
};

}  // namespace arview::app
