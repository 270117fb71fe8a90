#pragma once
// `arview view`: the scene's characters on a floor, seen by an orbit camera the user drives,
// animated by that camera's centre as the AR pipeline animates them by the tracked camera's,
// with the overlay and key authoring. The window and the headless orbit both render through
// this object; only where the camera comes from differs.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "anim_authoring/scene.h"
#include "app/pipeline/stage_stats.h"
#include "app/view/view_animation.h"
#include "app/view/view_authoring.h"
#include "app/view/view_camera.h"
#include "app/view/view_ground.h"
#include "video/window.h"
#include "render/ar_renderer.h"
#include "render/offscreen.h"

namespace arview::app {

struct ViewOptions {
  cv::Size size{1280, 720};
  double fov_deg = 45;
  render::OffscreenOptions gl;
  render::ArOptions ar;
  std::string character;  // the character keys are authored for (empty: the first)
  bool hud = true;
  bool help = true;
};

class ViewSession {
 public:
  // Loads the scene and every character; throws (one line naming the file) when it cannot.
  ViewSession(const std::filesystem::path& scene_file, const ViewOptions& options);
  ~ViewSession();

  // One input event at animation time `time`.
  void Handle(const video::InputEvent& event, double time);
  bool quit_requested() const { return quit_; }

  // The frame at animation time `time` for the current camera; stage times go to `stats`.
  cv::Mat Render(double time, StageStats* stats = nullptr);

  OrbitCamera& camera() { return orbit_; }
  const calib::Camera& intrinsics() const { return camera_; }
  // The default view: the edited character from azimuth 30°, elevation 15°, fitting the frame.
  OrbitState HomeView() const;
  double character_height() const { return edited().height(); }

  // Authoring (also bound to keys, see HelpLines).
  void AddKey(double time);
  void RemoveNearestKey();
  void Undo();
  void Save();
  void CycleChoice(int step);
  const KeyChoice& choice() const { return choices_[choice_]; }
  bool dirty() const { return editor_.dirty(); }
  const std::vector<authoring::KeySpec>& keys() const { return editor_.keys(); }
  const std::string& message() const { return message_; }

  // The state as one JSON object: camera, keys, and the viewpoint and weights the last frame
  // was animated with (the 'p' key prints it after the next frame).
  std::string StateJson() const;
  static std::vector<std::string> HelpLines();
  std::string renderer() const { return context_->Description(); }
  void set_fps(double fps) { fps_ = fps; }

 private:
  const ViewAnimation& edited() const { return *animations_[edited_]; }
  ViewAnimation& edited() { return *animations_[edited_]; }
  Eigen::Vector3d CurrentViewpoint() const;  // for the camera as it is now
  void ApplyKeys();  // the editor's keys to the animation (reverts the edit when they cannot be built)
  std::vector<std::string> StatusLines() const;
  void HandleKey(const video::InputEvent& e, double time);

  std::filesystem::path scene_file_;
  std::string scene_text_;  // as last read or written
  authoring::Scene scene_;       // parsed from scene_text_
  ViewOptions options_;
  calib::Camera camera_;
  std::vector<std::unique_ptr<ViewAnimation>> animations_;
  int edited_ = 0;
  KeyEditor editor_;
  std::vector<KeyChoice> choices_;
  int choice_ = 0;
  OrbitCamera orbit_;
  GroundGrid grid_;
  std::unique_ptr<render::OffscreenContext> context_;
  std::unique_ptr<render::ArRenderer> renderer_;
  cv::Mat ground_;
  std::optional<calib::Pose> ground_pose_;
  std::vector<const anim::AnimatorFrame*> outputs_;
  std::vector<double> weights_;  // the edited character's, last frame
  Eigen::Vector3d viewpoint_ = Eigen::Vector3d::UnitZ();
  double last_time_ = 0;
  double fps_ = 0;

  // Mouse drag.
  enum class Drag { kNone, kOrbit, kPan };
  Drag drag_ = Drag::kNone;
  int drag_x_ = 0, drag_y_ = 0;
  bool quit_ = false;
  bool print_after_frame_ = false;
  std::string message_;
};

}  // namespace arview::app
