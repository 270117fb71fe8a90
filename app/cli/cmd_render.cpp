// arview render --scene scene.yaml --camera camera.yaml --pose "tx ty tz qx qy qz qw"

#include "anim_authoring/character_builder.h"
#include "base/image_file.h"
//               [--background image.png] [--time s] [--hmd --ipd m] --out out.png
//               [--expression happy=0.8] [--morph "jawOpen=0.5,viseme_PP=1"]

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "anim_authoring/scene.h"
#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"
#include "app/placement/scene_lighting.h"
#include "calib/camera.h"
#include "figure/face_targets.h"
#include "map/map_file.h"
#include "render/ar_renderer.h"
#include "render/prt_cache.h"

namespace arview::app {

namespace {

struct RenderArgs {
  std::string scene, camera, pose, background, out;
  double time = 0;
  std::string skinning = "dq";
  bool hmd = false;
  double ipd = 0.064;
  std::string antialiasing = "msaa";
  bool no_shadow = false;
  std::string lighting = "auto", light;
  bool no_cast_shadow = false, no_occlusion = false;
  std::string expression, morph;
  GlFlags gl;
};

struct MorphSetting {
  std::string target;
  float weight;
};

// "NAME=W": a target's name and its weight, a finite number in [0, 1] (for --expression, "NAME"
// alone is intensity 1).
MorphSetting ParseNameWeight(const std::string& item, const char* flag, bool weight_optional) {
  const std::size_t eq = item.find('=');
  const std::string name = item.substr(0, eq);
  if (name.empty()) throw CommandError(std::string(flag) + ": \"" + item + "\" has no name before '='");
  if (eq == std::string::npos) {
    if (weight_optional) return {name, 1.0f};
    throw CommandError(std::string(flag) + ": \"" + item + "\" needs a weight: NAME=W with W in [0, 1]");
  }
  std::istringstream in(item.substr(eq + 1));
  double w = 0;
  std::string rest;
  if (!(in >> w) || (in >> rest) || !std::isfinite(w) || w < 0 || w > 1)
    throw CommandError(std::string(flag) + ": \"" + item + "\": the weight must be a number in [0, 1]");
  return {name, static_cast<float>(w)};
}

// The weights --expression and --morph set, in order (--morph's after, so they override).
std::vector<MorphSetting> ParseMorphSettings(const RenderArgs& args) {
  std::vector<MorphSetting> out;
  if (!args.expression.empty()) {
    const MorphSetting e = ParseNameWeight(args.expression, "--expression", true);
    bool known = false;
    std::string names;
    for (figure::Expression expression : figure::kExpressions) {
      names += std::string(names.empty() ? "" : ", ") + figure::ExpressionName(expression);
      if (e.target != figure::ExpressionName(expression)) continue;
      known = true;
      for (const figure::TargetWeight& w : figure::ExpressionWeights(expression, e.weight)) out.push_back({w.target, w.weight});
    }
    if (!known) throw CommandError("--expression: no expression \"" + e.target + "\" (known: " + names + ")");
  }
  std::istringstream items(args.morph);
  for (std::string item; std::getline(items, item, ',');)
    if (!item.empty()) out.push_back(ParseNameWeight(item, "--morph", false));
  return out;
}

// `frame`'s weights with `settings` applied, in `weights`; throws naming the asset and the
// target when the character has no such target.
void SetMorphWeights(const anim::Character& character, const std::vector<MorphSetting>& settings, const anim::AnimatorFrame& frame,
                     std::vector<float>& weights) {
  weights.assign(frame.morph_weights.begin(), frame.morph_weights.end());
  weights.resize(character.skeleton.morph_targets.size(), 0.0f);
  for (const MorphSetting& s : settings) {
    const int target = character.skeleton.FindMorphTarget(s.target);
    if (target < 0)
      throw CommandError(character.source + ": no morph target '" + s.target + "' (arview anim info " + character.source +
                         " lists them)");
    weights[target] = s.weight;
  }
}

// "tx ty tz qx qy qz qw", camera-to-world as in TUM trajectories.
calib::Pose ParsePose(const std::string& text) {
  std::istringstream in(text);
  double v[7];
  for (double& x : v) {
    if (!(in >> x)) throw CommandError("--pose needs 7 numbers \"tx ty tz qx qy qz qw\" (TUM, camera-to-world), got \"" + text + "\"");
  }
  std::string rest;
  if (in >> rest) throw CommandError("--pose has more than 7 numbers: \"" + text + "\"");
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) {
    throw CommandError("--pose quaternion (qx qy qz qw) is not of unit length: \"" + text + "\"");
  }
  for (double x : v) {
    if (!std::isfinite(x)) throw CommandError("--pose has a non-finite number: \"" + text + "\"");
  }
  // A camera no map can hold (maps keep their points and cameras within map::kMaxCoordinate):
  // at 1e308 the projection overflowed and an image was written, exit 0.
  const double farthest = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  if (farthest > map::kMaxCoordinate) {
    char message[160];
    std::snprintf(message, sizeof message, "--pose: the camera position (%g, %g, %g) lies beyond %g map units of the "
                  "origin, the limit of a map's coordinates", v[0], v[1], v[2], map::kMaxCoordinate);
    throw CommandError(message);
  }
  return calib::Pose::FromCameraToWorld(q.normalized(), {v[0], v[1], v[2]});
}

std::string Fixed3(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", x);
  return text;
}

void RunRender(const RenderArgs& args) {
  const calib::Pose pose = ParsePose(args.pose);
  calib::Camera camera;
  camera = calib::LoadCamera(args.camera);
  cv::Mat background;
  if (!args.background.empty()) {
    background = ReadImageFile(args.background, cv::IMREAD_COLOR);
  }
  const std::string ext = std::filesystem::path(args.out).extension().string();
  if (ext != ".png" && ext != ".jpg" && ext != ".jpeg") throw CommandError(args.out + ": --out must end in .png or .jpg");
  const std::vector<MorphSetting> morph_settings = ParseMorphSettings(args);
  const authoring::Scene scene = authoring::LoadScene(args.scene);
  if (scene.characters.empty()) throw CommandError(args.scene + ": the scene has no characters");
  const SceneLighting lighting = ResolveSceneLighting(args.scene, args.lighting, args.light);
  std::vector<std::unique_ptr<authoring::AnimatedCharacter>> characters;
  for (const authoring::CharacterSpec& spec : scene.characters) characters.push_back(std::make_unique<authoring::AnimatedCharacter>(spec));

  auto context = render::OffscreenContext::Create(ToOffscreenOptions(args.gl));
  render::ArOptions options;
  options.antialiasing = render::ParseAntialiasing(args.antialiasing);
  options.shadow = !args.no_shadow;
  options.skinning = args.skinning == "lbs" ? anim::SkinningMethod::kLinear : anim::SkinningMethod::kDualQuaternion;
  options.lighting = lighting.mode;
  options.prt_cache_folder = render::DefaultPrtCacheFolder();
  options.cast_shadow = !args.no_cast_shadow;
  options.occlusion = !args.no_occlusion;
  options.exposure_smoothing = 1.0;  // one frame: its own exposure
  render::ArRenderer renderer(*context, camera, options);
  if (lighting.light) renderer.SetRoomLight(*lighting.light);
  std::vector<const anim::AnimatorFrame*> frames;
  // Copies of the frames with --expression's and --morph's weights, and the weights they point at.
  std::vector<anim::AnimatorFrame> set_frames(characters.size());
  std::vector<std::vector<float>> set_weights(characters.size());
  for (std::size_t i = 0; i < characters.size(); ++i) {
    auto& c = characters[i];
    renderer.AddCharacter(c->character(), c->spec().placement());
    const anim::Placement placement = c->spec().placement();
    // The viewer's eyes are the camera: a character with gaze looks at it (anim/gaze.h).
    const anim::AnimatorFrame& frame =
        c->Update(placement.ViewpointFromCamera(pose.Center()), args.time, placement.MapToModel(pose.Center()));
    frames.push_back(&frame);
    if (morph_settings.empty()) continue;
    SetMorphWeights(c->character(), morph_settings, frame, set_weights[i]);
    set_frames[i] = frame;
    set_frames[i].morph_weights = set_weights[i];
    frames.back() = &set_frames[i];
  }
  const cv::Mat image = args.hmd ? renderer.RenderSideBySide(background, pose, frames, args.ipd)
                                 : renderer.Render(background, pose, frames);
  WriteImageAtomically(args.out, image);
  std::cout << "wrote " << args.out << " (" << image.cols << "x" << image.rows << ", "
            << characters.size() << " character" << (characters.size() == 1 ? "" : "s")
            << (camera.HasDistortion() ? ", undistorted view" : "")
            << (renderer.used_linear_fallback() ? ", linear skinning (joints scale)" : "") << ", lighting "
            << render::LightingModeName(lighting.mode)
            << (lighting.mode == render::LightingMode::kShShadowed ? " (PRT " + Fixed3(renderer.prt_seconds()) + " s" + (renderer.prt_from_cache() > 0 ? ", from its cache" : "") + ")" : "")
            << ") ["
            << context->Description() << "]\n";
}

}  // namespace

void AddRenderCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render one frame of a scene from a given camera pose");
  auto args = std::make_shared<RenderArgs>();
  cmd->add_option("--scene", args->scene, "Scene file (YAML, see docs/anim.md)")->required();
  cmd->add_option("--camera", args->camera, "camera.yaml (OpenCV FileStorage)")->required();
  cmd->add_option("--pose", args->pose, "Camera pose \"tx ty tz qx qy qz qw\": camera-to-world, as a TUM trajectory line without its timestamp")
      ->required();
  cmd->add_option("--background", args->background, "Camera image to draw over (the camera's size); default: grey");
  cmd->add_option("--out", args->out, "Output image (.png or .jpg)")->required();
  cmd->add_option("--time", args->time, "Animation time, seconds")->default_val(args->time);
  cmd->add_option("--skinning", args->skinning, "dq (dual quaternion) or lbs (linear blend)")
      ->default_val(args->skinning)
      ->check(CLI::IsMember({"dq", "lbs"}));
  cmd->add_flag("--hmd", args->hmd, "Side-by-side stereo for a head-mounted display (2W x H)");
  cmd->add_option("--ipd", args->ipd, "Interpupillary distance for --hmd, metres")->default_val(args->ipd)->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--aa", args->antialiasing, "Antialiasing: msaa (4x multisampling) or none")
      ->default_val(args->antialiasing)
      ->check(CLI::IsMember({"msaa", "none"}));
  cmd->add_flag("--no-shadow", args->no_shadow, "No contact shadow");
  cmd->add_option("--lighting", args->lighting,
                  "auto (prt when the scene has a .light.yml), fixed (key + ambient), sh (room SH, unshadowed) or prt "
                  "(room SH through self-shadowed PRT)")
      ->default_val(args->lighting)
      ->check(CLI::IsMember({"auto", "fixed", "sh", "prt"}));
  cmd->add_option("--light", args->light, "Room light file (default: the scene's <scene>.light.yml)");
  cmd->add_flag("--no-cast-shadow", args->no_cast_shadow, "No shadow from the room's dominant light");
  cmd->add_flag("--no-occlusion", args->no_occlusion, "Do not let the scene proxy hide the character");
  cmd->add_option("--expression", args->expression,
                  "NAME[=INTENSITY]: the built-in figure's expression (happy, sad, angry, surprised, afraid, disgusted) "
                  "at an intensity in [0, 1] (default 1), as its morph targets' weights (docs/figure.md)");
  cmd->add_option("--morph", args->morph,
                  "\"NAME=W[,NAME=W...]\": morph target weights in [0, 1] on every character, over the animation's "
                  "and --expression's (arview anim info lists a character's targets)");
  AddGlFlags(cmd, args->gl);
  cmd->callback([args] { RunRender(*args); });
}

}  // namespace arview::app
