#include "app/pipeline/ar_compositor.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdio>

#include "anim/character_bounds.h"
#include "render/hud.h"
#include "render/projection.h"

namespace arview::app {

void CompositorOptions::Check(const OptionNames& names) const {
  // One view of the character per eye needs the eyes: the side-by-side output.
  if (stereo_character && !hmd) throw OptionError(names("stereo_character") + " needs " + names("hmd"));
  RequireOption(ipd_m >= 0, names("ipd_m"), "0 or more", ipd_m);
}

ArCompositor::ArCompositor(const calib::Camera& camera, std::vector<const anim::PlacedCharacter*> characters,
                           const CompositorOptions& options, std::unique_ptr<render::OffscreenContext> context)
    : camera_(camera), characters_(std::move(characters)), options_(options), hud_visible_(options.hud) {
  // Created before the pipeline's threads start: creating a context sets LP_NUM_THREADS in the
  // environment, which must not race with other threads.
  context_ = context ? std::move(context) : render::OffscreenContext::Create(options_.gl);
  renderer_ = std::make_unique<render::ArRenderer>(*context_, camera_, options_.ar);
  if (options_.room_light) renderer_->SetRoomLight(*options_.room_light);
  for (const anim::PlacedCharacter* c : characters_) {
    renderer_->AddCharacter(c->character(), c->placement());
    heights_.push_back(anim::RestHeightInMap(c->character(), c->placement()));
  }
  if (options_.ar.lighting == render::LightingMode::kShShadowed && !characters_.empty()) {
    char line[96];
    std::snprintf(line, sizeof line, "PRT transfer: %s in %.2f s", renderer_->prt_from_cache() > 0 ? "read from its cache" : "computed",
                  renderer_->prt_seconds());
    load_notes_.push_back(line);
    if (!renderer_->prt_cache_note().empty()) load_notes_.push_back(renderer_->prt_cache_note());
  }
  description_ = context_->Description();
  if (options_.hmd && options_.hmd_profile) presenter_.emplace(*options_.hmd_profile, renderer_->pinhole());
  context_->ReleaseCurrent();  // for the render thread (BindToThread)
}

std::vector<std::string> DialogueHudLines(const CharacterDialogue& dialogue) {
  const DialogueFrame& d = dialogue.frame();
  std::vector<std::string> lines;
  char line[192];
  if (!dialogue.last_heard().empty()) {
    std::snprintf(line, sizeof line, "heard: \"%.80s\" (confidence %.2f%s)", dialogue.last_heard().c_str(),
                  d.heard_confidence, d.heard_accepted ? "" : ", not taken");
    lines.push_back(line);
  } else {
    lines.push_back(d.listening ? "heard: nothing yet" : "heard: not listening");
  }
  if (d.push_to_talk) {
    const std::string key(kPushToTalkKey);
    lines.push_back(d.talking ? "talk: listening, press " + key + " when done" : "talk: press " + key + " to speak");
  }
  std::snprintf(line, sizeof line, "machine: %.*s   emotion: %.*s %.2f   face: %.*s %.2f",
                static_cast<int>(d.machine.empty() ? 1 : d.machine.size()), d.machine.empty() ? "-" : d.machine.data(),
                static_cast<int>(d.emotion.empty() ? 7 : d.emotion.size()), d.emotion.empty() ? "neutral" : d.emotion.data(),
                d.emotion_intensity, static_cast<int>(d.expression.empty() ? 7 : d.expression.size()),
                d.expression.empty() ? "neutral" : d.expression.data(), d.expression_weight);
  lines.push_back(line);
  return lines;
}

std::vector<std::string> ArCompositor::HudStatus(const FrameToCompose& input) const {
  char line[128];
  std::snprintf(line, sizeof line, "frame %lld   %s   %.0f frames/s", static_cast<long long>(input.frame->index),
                ToString(input.track->status).c_str(), composed_.PerSecond());
  std::vector<std::string> status = {line};
  if (input.track->status == tracker::TrackStatus::kLost) {
    // Why, while it happens: what the user can change now (light, speed, where the camera points).
    if (input.loss) status.push_back("lost: " + tracker::LossHeadline(*input.loss));
    if (!characters_.empty()) status.push_back("lost: the character is hidden until the camera is found again");
  } else if (!input.animations.empty()) {
    std::snprintf(line, sizeof line, "idle weight %.2f", input.animations.front()->idle_weight());
    status.push_back(line);
    if (std::string eyes = render::EyeContactLine(input.animations.front()->gaze); !eyes.empty()) status.push_back(eyes);
  }
  if (input.dialogue) {
    for (std::string& l : DialogueHudLines(*input.dialogue)) status.push_back(std::move(l));
  }
  return status;
}

ArCompositor::HudDraw ArCompositor::MakeHud(const FrameToCompose& input) {
  // Without a character the HUD still says what the tracker does (and, when lost, why).
  // The room is followed on every frame, so that a HUD shown again knows where the camera came from.
  std::vector<std::string> room_lines = room_hud_.Update(input.track->room, input.frame->timestamp);
  if (!hud_visible_) return {};
  // Everything the drawing needs is copied now: the animations' frames change with the next one.
  std::vector<render::HudSphere> spheres;
  const bool localized = input.track->status != tracker::TrackStatus::kLost;
  for (size_t i = 0; localized && i < characters_.size() && i < input.animations.size(); ++i) {
    const anim::AnimatorFrame& a = *input.animations[i];
    const anim::PlacedCharacter& c = *characters_[i];
    spheres.push_back(render::HudSphereFor(c.placement(), c.name(), c.key_viewpoints(), c.key_labels(), a.key_weights,
                                           a.viewpoint, heights_[i]));
  }
  render::HudText text;
  text.status = HudStatus(input);
  text.status.insert(text.status.begin() + 1, room_lines.begin(), room_lines.end());  // under the frame's line
  const calib::Pose pose = localized ? input.track->pose : calib::Pose{};
  return [spheres = std::move(spheres), text = std::move(text), pose, camera = renderer_->pinhole()](
             cv::Mat& view, double eye_offset_m) {
    render::DrawHud(view, camera, eye_offset_m == 0 ? pose : render::OffsetEye(pose, eye_offset_m), spheres, text);
  };
}

std::function<void(cv::Mat&)> ArCompositor::DeferredOverlay(const FrameToCompose& input) {
  if (presenter_) return {};  // drawn into the eyes' views before the pre-distortion (Compose)
  HudDraw hud = MakeHud(input);
  if (!hud) return {};
  if (!options_.hmd) return [hud = std::move(hud)](cv::Mat& frame) { hud(frame, 0); };
  const double half_ipd = options_.stereo_character ? 0.5 * options_.ipd_m : 0.0;
  return [hud = std::move(hud), half_ipd, width = camera_.width, height = camera_.height](cv::Mat& frame) {
    for (int eye = 0; eye < 2; ++eye) {
      cv::Mat half = frame(cv::Rect(eye * width, 0, width, height));
      hud(half, eye == 0 ? -half_ipd : half_ipd);
    }
  };
}

namespace {

// From in front of the character and a little above, looking at its middle.
calib::Pose InFrontOf(const anim::Placement& placement, double height) {
  const Eigen::Matrix3d rotation = placement.Rotation();
  const Eigen::Vector3d origin = placement.ModelToMap().col(3).head<3>();
  const Eigen::Vector3d up = (rotation * placement.up).normalized();
  const Eigen::Vector3d front = (rotation * placement.forward).normalized();
  const double h = height > 0 ? height : 1.0;
  const Eigen::Vector3d eye = origin + 2.5 * h * front + 0.6 * h * up, target = origin + 0.5 * h * up;
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  Eigen::Matrix3d r_wc;
  r_wc << right, forward.cross(right), forward;  // camera x right, y down, z forward
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), eye);
}

}  // namespace

double ArCompositor::WarmUp() {
  if (characters_.empty()) return 0;
  const auto start = std::chrono::steady_clock::now();
  context_->MakeCurrent();
  std::vector<anim::FrameBuffers> buffers;
  buffers.reserve(characters_.size());
  std::vector<anim::AnimatorFrame> frames(characters_.size());
  std::vector<const anim::AnimatorFrame*> frame_ptrs;
  for (size_t i = 0; i < characters_.size(); ++i) {
    const anim::Skeleton& skeleton = characters_[i]->character().skeleton;
    buffers.emplace_back(skeleton);
    buffers.back().Finish(skeleton, frames[i], "warm-up pose", "warm-up skinning");
    frame_ptrs.push_back(&frames[i]);
  }
  const calib::Pose pose = InFrontOf(characters_[0]->placement(), heights_[0]);
  if (options_.hmd && options_.stereo_character) {
    renderer_->WarmUp(render::OffsetEye(pose, -0.5 * options_.ipd_m), frame_ptrs);
  } else {
    renderer_->WarmUp(pose, frame_ptrs);
  }
  context_->ReleaseCurrent();  // for the render thread (BindToThread)
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The context is made on the constructing thread and used on the render thread: EGL lets a
// context be current on one thread at a time, so each hands it over explicitly.
void ArCompositor::BindToThread() { context_->MakeCurrent(); }
void ArCompositor::UnbindFromThread() { context_->ReleaseCurrent(); }

void ArCompositor::MoveCharacter(size_t index, const anim::Placement& placement) {
  renderer_->MoveCharacter(static_cast<int>(index), placement);
  heights_.at(index) = anim::RestHeightInMap(characters_.at(index)->character(), placement);
}

ArCompositor::~ArCompositor() {
  // The renderer's GL objects are deleted on this thread: the context must be current here.
  try {
    context_->MakeCurrent();
  } catch (const render::RenderError&) {
    // Not current: the driver frees the objects with the context.
  }
}

cv::Size ArCompositor::OutputSizeFor(const calib::Camera& camera, const CompositorOptions& options) {
  if (options.hmd && options.hmd_profile) return options.hmd_profile->panel;
  return {options.hmd ? 2 * camera.width : camera.width, camera.height};
}

cv::Size ArCompositor::OutputSize() const { return OutputSizeFor(camera_, options_); }

cv::Mat ArCompositor::Compose(const FrameToCompose& input) {
  composed_.Add(std::chrono::steady_clock::now());
  const bool localized = input.track->status != tracker::TrackStatus::kLost;
  output_ptrs_.clear();
  if (localized) output_ptrs_.assign(input.animations.begin(), input.animations.end());
  if (options_.hmd) return ComposeForHmd(input, localized);
  if (localized || characters_.empty()) {
    return renderer_->Render(input.frame->image, localized ? input.track->pose : calib::Pose{}, output_ptrs_);
  }
  return VideoAlone(input).clone();  // the HUD, drawn by DeferredOverlay, says "lost"
}

cv::Mat ArCompositor::ComposeForHmd(const FrameToCompose& input, bool localized) {
  const calib::Pose pose = localized ? input.track->pose : calib::Pose{};
  cv::Mat left, right;
  if (!localized && !characters_.empty()) {
    left = right = VideoAlone(input).clone();
  } else if (options_.stereo_character) {
    const cv::Mat both = renderer_->RenderSideBySide(input.frame->image, pose, output_ptrs_, options_.ipd_m);
    left = both(cv::Rect(0, 0, camera_.width, camera_.height));
    right = both(cv::Rect(camera_.width, 0, camera_.width, camera_.height));
  } else {
    left = right = renderer_->Render(input.frame->image, pose, output_ptrs_);  // biocular: one render
  }
  if (!presenter_) {
    cv::Mat out;
    cv::hconcat(left, right, out);
    return out;
  }
  if (HudDraw hud = MakeHud(input)) {
    const double half_ipd = options_.stereo_character ? 0.5 * options_.ipd_m : 0.0;
    if (left.data == right.data) {
      hud(left, 0);
    } else {
      hud(left, -half_ipd);
      hud(right, half_ipd);
    }
  }
  return presenter_->Present(left, right);
}

cv::Mat ArCompositor::VideoAlone(const FrameToCompose& input) {
  // No pose to register the characters with, so the video is shown alone, undistorted like the
  // augmented frames (the renderer's maps: same K, pinhole output).
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
  return frame;
}

}  // namespace arview::app
