#include "app/view/view_session.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "base/atomic_file.h"
#include "app/view/view_hud.h"
#include "render/hud.h"

namespace arview::app {

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string ReadText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string Fixed(double v, int digits = 1) {
  char t[32];
  std::snprintf(t, sizeof t, "%.*f", digits, v);
  return t;
}

bool SamePose(const calib::Pose& a, const calib::Pose& b) {
  return a.q_cw.coeffs() == b.q_cw.coeffs() && a.t_cw == b.t_cw;
}

}  // namespace

ViewSession::ViewSession(const std::filesystem::path& scene_file, const ViewOptions& options)
    : scene_file_(scene_file), options_(options), camera_(ViewCamera(options.size.width, options.size.height, options.fov_deg)) {
  scene_text_ = ReadText(scene_file_);
  scene_ = authoring::ParseScene(scene_text_, scene_file_);
  if (scene_.characters.empty()) throw std::runtime_error(scene_file_.string() + ": has no character");
  edited_ = -1;
  for (size_t i = 0; i < scene_.characters.size(); ++i) {
    if (options.character.empty() ? i == 0 : scene_.characters[i].name == options.character) edited_ = static_cast<int>(i);
  }
  if (edited_ < 0) throw std::runtime_error(scene_file_.string() + ": no character named '" + options.character + "'");
  for (const authoring::CharacterSpec& spec : scene_.characters) {
    animations_.push_back(std::make_unique<ViewAnimation>(spec));
    for (const std::string& note : animations_.back()->notes()) std::cerr << "note: " << note << "\n";
  }
  editor_ = KeyEditor(edited().keys());
  choices_ = KeyChoices(edited().asset());

  const authoring::CharacterSpec& spec = edited().spec();
  const Eigen::Matrix3d rotation = spec.anchor.rotation.normalized().toRotationMatrix();
  const Eigen::Vector3d up = (rotation * spec.up).normalized(), forward = rotation * spec.forward;
  orbit_ = OrbitCamera(forward, up, HomeView());
  grid_.origin = spec.anchor.position;
  grid_.forward = forward;
  grid_.up = up;
  grid_.cell = GridCellFor(edited().height());

  // The context before any other thread exists (it sets LP_NUM_THREADS).
  context_ = render::OffscreenContext::Create(options_.gl);
  renderer_ = std::make_unique<render::ArRenderer>(*context_, camera_, options_.ar);
  for (const auto& a : animations_) renderer_->AddCharacter(a->asset(), a->spec().placement());
  message_ = "loaded " + scene_file_.string();
}

ViewSession::~ViewSession() = default;

OrbitState ViewSession::HomeView() const {
  const authoring::CharacterSpec& spec = edited().spec();
  const Eigen::Vector3d up = (spec.anchor.rotation.normalized() * spec.up).normalized();
  const double h = edited().height();
  OrbitState s;
  s.target = spec.anchor.position + 0.5 * h * up;
  s.azimuth_deg = 30;
  s.elevation_deg = 15;
  // The view sphere (radius 1.1 h) fits in the frame's height, with a margin.
  s.distance = 1.3 * 1.1 * h / std::tan(0.5 * options_.fov_deg * M_PI / 180);
  return s;
}

cv::Mat ViewSession::Render(double time, StageStats* stats) {
  last_time_ = time;
  const calib::Pose pose = orbit_.Pose();
  const Eigen::Vector3d centre = orbit_.Center();
  Clock::time_point t0 = Clock::now();
  outputs_.clear();
  for (const auto& a : animations_) outputs_.push_back(&a->Update(centre, time));
  weights_.assign(outputs_[edited_]->key_weights.begin(), outputs_[edited_]->key_weights.end());
  viewpoint_ = edited().viewpoint();
  if (stats) stats->Record("animate", MsSince(t0));

  t0 = Clock::now();
  if (!ground_pose_ || !SamePose(*ground_pose_, pose)) {
    ground_ = RenderGround(grid_, camera_, pose);
    ground_pose_ = pose;
  }
  if (stats) stats->Record("floor", MsSince(t0));
  t0 = Clock::now();
  cv::Mat frame = renderer_->Render(ground_, pose, outputs_);
  if (stats) stats->Record("render", MsSince(t0));
  if (options_.hud) {
    t0 = Clock::now();
    std::vector<render::HudSphere> spheres;
    const int nearest = editor_.Nearest(viewpoint_);
    spheres.push_back(HudSphereFor(edited().spec(), weights_, viewpoint_, edited().height(), nearest));
    render::HudText text;
    text.status = StatusLines();
    if (options_.help) text.help = HelpLines();
    render::DrawHud(frame, camera_, pose, spheres, text);
    if (stats) stats->Record("hud", MsSince(t0));
  }
  if (print_after_frame_) {
    // After the frame, so that the state printed is the one it shows.
    std::printf("%s\n", StateJson().c_str());
    std::fflush(stdout);
    print_after_frame_ = false;
  }
  return frame;
}

std::vector<std::string> ViewSession::HelpLines() {
  return {
      "drag: orbit   right- or shift-drag: pan   wheel or +/-: zoom   arrows: orbit 5 deg   r: reset view",
      "[ and ]: what a new key plays   a: add a key here   x or Delete: remove the nearest key   u: undo",
      "s: save the scene   h: overlay on/off   ?: help on/off   p: print the state   q or Esc: quit",
  };
}

std::vector<std::string> ViewSession::StatusLines() const {
  const authoring::CharacterSpec& spec = edited().spec();
  const Eigen::Vector2d ae = AzimuthElevation(viewpoint_, spec.forward, spec.up);
  std::vector<std::string> lines;
  lines.push_back(scene_file_.filename().string() + (dirty() ? " (unsaved changes)" : "") + "   character " + spec.name +
                  "   " + std::to_string(keys().size()) + " keys");
  lines.push_back("viewpoint: azimuth " + Fixed(ae.x()) + ", elevation " + Fixed(ae.y()) + " deg   distance " +
                  Fixed(orbit_.state().distance, 2));
  lines.push_back("a new key plays: " + choice().label + "   ([ ] to change)");
  if (!message_.empty()) lines.push_back(message_);
  if (fps_ > 0) lines.push_back(Fixed(fps_) + " frames/s");
  return lines;
}

void ViewSession::Handle(const video::InputEvent& e, double time) {
  switch (e.type) {
    case video::InputEvent::Type::kClose: quit_ = true; return;
    case video::InputEvent::Type::kKey: HandleKey(e, time); return;
    case video::InputEvent::Type::kPress:
      if (e.button == 4 || e.button == 5) {
        orbit_.Zoom(e.button == 4 ? 1 : -1);
        return;
      }
      drag_ = (e.button == 3 || e.button == 2 || (e.button == 1 && e.shift)) ? Drag::kPan
              : e.button == 1                                              ? Drag::kOrbit
                                                                           : Drag::kNone;
      drag_x_ = e.x, drag_y_ = e.y;
      return;
    case video::InputEvent::Type::kRelease:
    case video::InputEvent::Type::kMotion: {
      const int dx = e.x - drag_x_, dy = e.y - drag_y_;
      if (drag_ == Drag::kOrbit) orbit_.Orbit(dx, dy);
      if (drag_ == Drag::kPan) orbit_.Pan(dx, dy, camera_);
      drag_x_ = e.x, drag_y_ = e.y;
      if (e.type == video::InputEvent::Type::kRelease) drag_ = Drag::kNone;
      return;
    }
  }
}

void ViewSession::HandleKey(const video::InputEvent& e, double time) {
  const std::string& k = e.key;
  if (k == "q" || k == "Escape") quit_ = true;
  else if (k == "h") options_.hud = !options_.hud;
  else if (k == "question" || k == "slash" || k == "F1") options_.help = !options_.help;
  else if (k == "bracketright" || k == "Tab") CycleChoice(1);
  else if (k == "bracketleft" || k == "ISO_Left_Tab") CycleChoice(-1);
  else if (k == "a" || k == "Insert") AddKey(time);
  else if (k == "x" || k == "Delete") RemoveNearestKey();
  else if (k == "u" || (k == "z" && e.control)) Undo();
  else if (k == "s") Save();
  else if (k == "r" || k == "Home") orbit_.Reset();
  else if (k == "p") print_after_frame_ = true;
  else if (k == "Left") orbit_.Orbit(5 / OrbitCamera::kDegPerPixel, 0);
  else if (k == "Right") orbit_.Orbit(-5 / OrbitCamera::kDegPerPixel, 0);
  else if (k == "Up") orbit_.Orbit(0, 5 / OrbitCamera::kDegPerPixel);
  else if (k == "Down") orbit_.Orbit(0, -5 / OrbitCamera::kDegPerPixel);
  else if (k == "plus" || k == "equal" || k == "KP_Add") orbit_.Zoom(1);
  else if (k == "minus" || k == "KP_Subtract") orbit_.Zoom(-1);
}

void ViewSession::CycleChoice(int step) {
  const int n = static_cast<int>(choices_.size());
  choice_ = ((choice_ + step) % n + n) % n;
  message_ = "a new key plays " + choice().label;
}

void ViewSession::ApplyKeys() {
  try {
    edited().SetKeys(editor_.keys());
  } catch (const std::exception& e) {
    editor_.Undo();
    throw;
  }
}

void ViewSession::AddKey(double time) {
  const authoring::CharacterSpec& spec = edited().spec();
  const authoring::KeySpec key = MakeKey(CurrentViewpoint(), choice(), edited().asset(), spec, time);
  editor_.Add(key);
  try {
    ApplyKeys();
  } catch (const std::exception& e) {
    message_ = std::string("cannot add that key: ") + e.what();
    return;
  }
  const Eigen::Vector2d ae = AzimuthElevation(key.viewpoint, spec.forward, spec.up);
  message_ = "added key " + std::to_string(keys().size() - 1) + " (" + KeySourceLabel(key) + ") at azimuth " +
             Fixed(ae.x(), 2) + ", elevation " + Fixed(ae.y(), 2);
}

void ViewSession::RemoveNearestKey() {
  const int k = editor_.Nearest(CurrentViewpoint());
  const std::string label = KeySourceLabel(keys()[k]);
  try {
    editor_.Remove(k);
    ApplyKeys();
  } catch (const std::exception& e) {
    message_ = std::string("cannot remove: ") + e.what();
    return;
  }
  message_ = "removed key " + std::to_string(k) + " (" + label + ")";
}

void ViewSession::Undo() {
  if (!editor_.Undo()) {
    message_ = "nothing to undo";
    return;
  }
  try {
    edited().SetKeys(editor_.keys());
  } catch (const std::exception& e) {
    message_ = std::string("cannot undo: ") + e.what();
    return;
  }
  message_ = "undone: " + std::to_string(keys().size()) + " keys";
}

void ViewSession::Save() {
  try {
    // Someone may have edited the file since it was read: never overwrite their change.
    if (ReadText(scene_file_) != scene_text_) {
      throw std::runtime_error(scene_file_.string() + " changed on disk since it was read; not overwritten");
    }
    const std::string text = SpliceKeys(scene_text_, scene_, edited_, editor_.keys(), editor_.FileOrigins());
    authoring::Scene reread = ValidateSceneText(text, scene_file_, edited_, editor_.keys());
    WriteFileAtomically(scene_file_, text);
    scene_text_ = text;
    scene_ = std::move(reread);
    editor_.MarkSaved();
    message_ = "saved " + scene_file_.string() + " (" + std::to_string(keys().size()) + " keys)";
  } catch (const std::exception& e) {
    message_ = std::string("not saved: ") + e.what();
  }
  std::fprintf(stderr, "view: %s\n", message_.c_str());
}

Eigen::Vector3d ViewSession::CurrentViewpoint() const {
  const Eigen::Vector3d v = edited().spec().placement().ViewpointFromCamera(orbit_.Center());
  return v.squaredNorm() > 0 ? v : viewpoint_;
}

std::string ViewSession::StateJson() const {
  const authoring::CharacterSpec& spec = edited().spec();
  // What the last frame showed: the viewpoint and weights the animation used for it.
  const Eigen::Vector3d& viewpoint = viewpoint_;
  const std::vector<double>& weights = weights_;
  nlohmann::json j;
  const OrbitState& s = orbit_.state();
  const Eigen::Vector3d c = orbit_.Center();
  j["camera"] = {{"azimuth_deg", s.azimuth_deg},
                 {"elevation_deg", s.elevation_deg},
                 {"distance", s.distance},
                 {"target", {s.target.x(), s.target.y(), s.target.z()}},
                 {"center", {c.x(), c.y(), c.z()}}};
  j["character"] = spec.name;
  j["viewpoint"] = {viewpoint.x(), viewpoint.y(), viewpoint.z()};
  const Eigen::Vector2d ae = AzimuthElevation(viewpoint, spec.forward, spec.up);
  j["viewpoint_azimuth_deg"] = ae.x();
  j["viewpoint_elevation_deg"] = ae.y();
  j["time_s"] = last_time_;
  j["keys"] = nlohmann::json::array();
  for (size_t k = 0; k < keys().size(); ++k) {
    const authoring::KeySpec& key = keys()[k];
    j["keys"].push_back({{"index", k},
                         {"plays", KeySourceLabel(key)},
                         {"viewpoint", {key.viewpoint.x(), key.viewpoint.y(), key.viewpoint.z()}},
                         {"weight", k < weights.size() ? weights[k] : 0.0}});
  }
  j["choice"] = choice().label;
  j["unsaved"] = dirty();
  j["message"] = message_;
  return j.dump();
}

}  // namespace arview::app
