#include "render/ar_renderer.h"

#include "render/prt_cache.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <limits>

namespace arview::render {

Antialiasing ParseAntialiasing(const std::string& name) {
  if (name == "msaa") return Antialiasing::kMsaa;
  if (name == "none") return Antialiasing::kNone;
  throw RenderError("unknown antialiasing '" + name + "' (expected msaa or none)");
}

ArRenderer::ArRenderer(OffscreenContext& context, const calib::Camera& camera, const ArOptions& options)
    : context_(&context),
      camera_(camera),
      pinhole_(camera.WithoutDistortion()),
      options_(options),
      target_(context.gl(), camera.Size(), options.antialiasing == Antialiasing::kMsaa ? 4 : 0),
      shadow_(context.gl()) {
  pixel_buffer_readback_ = options.readback == Readback::kPixelBuffer ||
                           (options.readback == Readback::kAuto && !context.info().software);
  ProjectionMatrix(pinhole_, options_.clip);  // validates the camera and the clip range
  if (camera_.HasDistortion()) {
    cv::initUndistortRectifyMap(camera_.K(), camera_.DistCoeffs(), cv::noArray(), camera_.K(), camera_.Size(),
                                CV_16SC2, undistort_map1_, undistort_map2_);
  }
}

void ArRenderer::MoveCharacter(int index, const anim::Placement& placement) {
  if (index < 0 || index >= static_cast<int>(characters_.size())) {
    throw RenderError("MoveCharacter: no character " + std::to_string(index) + " (" +
                      std::to_string(characters_.size()) + " added)");
  }
  characters_[index].placement = placement;
}

int ArRenderer::AddCharacter(const anim::Character& character, const anim::Placement& placement) {
  characters_.push_back({&character, placement, std::make_unique<CharacterRenderer>(context_->gl(), character),
                         FitShadowCapsules(character), false, LightView{}, cv::Mat()});
  characters_.back().renderer->set_cpu_morph_max_deltas(options_.cpu_morph_max_deltas);
  if (options_.lighting == LightingMode::kShShadowed) {
    const PrtCacheResult prt = ShadowedTransferCached(character, options_.prt, options_.prt_cache_folder);
    characters_.back().renderer->SetTransfer(prt.transfer);
    prt_seconds_ += prt.transfer.seconds;
    prt_from_cache_ += prt.from_cache;
    if (!prt.note.empty()) prt_cache_note_ += (prt_cache_note_.empty() ? "" : "; ") + prt.note;
  }
  return static_cast<int>(characters_.size()) - 1;
}

void ArRenderer::SetRoomLight(const room::RoomLight& light) {
  room_light_ = light;
  has_room_light_ = true;
  current_sh_ = light.sh;
  follower_ = std::make_unique<room::ExposureFollower>(light.thumbnails, light.scene_triangles, camera_, options_.exposure_smoothing);
  frames_since_exposure_ = 0;
  SetOccluders(light.occluder_triangles);
}

void ArRenderer::SetOccluders(const std::vector<Eigen::Vector3f>& triangles) {
  occluder_triangles_.assign(triangles.begin(), triangles.begin() + static_cast<std::ptrdiff_t>(triangles.size() / 3 * 3));
  if (triangles.empty()) {
    occluders_.reset();
    return;
  }
  occluders_ = std::make_unique<DepthProxy>(context_->gl(), triangles);
}

void ArRenderer::FollowExposure(const cv::Mat& background, const calib::Pose& pose) {
  if (options_.lighting == LightingMode::kFixed) return;
  if (!has_room_light_) {
    throw RenderError("lighting '" + LightingModeName(options_.lighting) +
                      "' needs the room's light (a .light.yml from 'arview place --recording')");
  }
  // The exposure is followed every kExposureEvery-th frame (its cost, ~1 ms of CPU for the
  // thumbnail and its rays, is then spread; cameras change exposure over several frames).
  const bool due = frames_since_exposure_++ % kExposureEvery == 0;
  const Eigen::Vector3d gain = background.empty() || !due ? follower_->gain() : follower_->Update(background, pose);
  current_sh_ = room::Scaled(room_light_.sh, gain);
}

void ArRenderer::UpdateCastShadows(std::span<const anim::AnimatorFrame* const> frames) {
  if (frames.size() != characters_.size()) {
    throw RenderError("AR render: " + std::to_string(characters_.size()) + " characters but " +
                      std::to_string(frames.size()) + " animation frames");
  }
  for (size_t i = 0; i < characters_.size(); ++i) {
    Placed& placed = characters_[i];
    placed.casts = CastShadowView(placed, *frames[i], &placed.light_view, &placed.coverage);
  }
}

bool ArRenderer::CastShadowView(const Placed& placed, const anim::AnimatorFrame& frame, LightView* view,
                                cv::Mat* coverage) const {
  if (!options_.cast_shadow || !has_room_light_ || frame.model.empty() || placed.capsules.empty()) return false;
  const anim::Placement& placement = placed.placement;
  const Eigen::Matrix4d model_to_map = placement.ModelToMap();
  std::vector<Eigen::Matrix4d> joint_to_map(frame.model.size());
  for (size_t j = 0; j < frame.model.size(); ++j) joint_to_map[j] = model_to_map * frame.model[j];
  const std::vector<ShadowCapsule> posed = PoseShadowCapsules(placed.capsules, joint_to_map);
  if (posed.empty()) return false;
  // The light view around the posed capsules, widened by the soft edge.
  Eigen::Vector3d centre;
  double radius = 0;
  CapsuleBounds(posed, &centre, &radius);
  const double soft = options_.cast_shadow_softness * 2 * radius;
  const Eigen::Vector3d normal = placement.UpInMap();
  // Below 15 degrees of elevation the shadow would stretch across the room: none.
  if (!MakeLightView(room_light_.dominant.direction, centre, radius + soft, placement.anchor.position, normal, 15.0, view)) {
    return false;
  }
  cv::Rect support;
  CapsuleCoverage(posed, view->map_to_clip, soft / (radius + soft), kCastShadowTexels, coverage, &support);
  if (support.empty()) return false;
  // The floor quad only under the covered texels, and one more texel each side for the bilinear
  // tap: the pixels DarkenCastShadow visits.
  const double texel = 2.0 / kCastShadowTexels;
  view->BoundFloor(-1 + (support.x - 1) * texel, -1 + (support.x + support.width + 1) * texel,
                   -1 + (support.y - 1) * texel, -1 + (support.y + support.height + 1) * texel);
  return true;
}

float ArRenderer::CastShadowStrength(const Placed& placed) const {
  // The share of the floor's irradiance the dominant light brings: what the character's shadow removes.
  const Eigen::Vector3d normal = placed.placement.UpInMap();
  const Eigen::Vector3d w = room::LuminanceWeights();
  const double total = room::IrradianceSh(room_light_.sh, normal).dot(w);
  const double direct = room_light_.dominant.color.dot(w) * std::max(0.0, room_light_.dominant.direction.dot(normal));
  if (!(total > 0)) return 0.f;
  return static_cast<float>(std::clamp(direct / total, 0.0, double(options_.cast_shadow_max_strength)));
}

cv::Mat ArRenderer::PrepareBackground(const cv::Mat& background) {
  if (background.empty()) return cv::Mat(camera_.Size(), CV_8UC3, options_.empty_background);
  if (background.size() != camera_.Size() || background.depth() != CV_8U ||
      (background.channels() != 1 && background.channels() != 3)) {
    throw RenderError("background image is " + std::to_string(background.cols) + "x" +
                      std::to_string(background.rows) + " with " + std::to_string(background.channels()) +
                      " channels; the camera is " + std::to_string(camera_.width) + "x" +
                      std::to_string(camera_.height) + " (8-bit BGR or grey expected)");
  }
  cv::Mat bgr;
  if (background.channels() == 1) cv::cvtColor(background, bgr, cv::COLOR_GRAY2BGR);
  else bgr = background;
  if (!camera_.HasDistortion()) return bgr.clone();
  cv::Mat undistorted;
  cv::remap(bgr, undistorted, undistort_map1_, undistort_map2_, cv::INTER_LINEAR);
  return undistorted;
}

bool ArRenderer::Shadow(const Placed& placed, const anim::AnimatorFrame& frame, ShadowEllipse* ellipse) const {
  const anim::Placement& placement = placed.placement;
  const Eigen::Matrix4d model_to_map = placement.ModelToMap();
  const Eigen::Matrix3d rotation = placement.Rotation();
  const Eigen::Vector3d origin = placement.anchor.position;
  const Eigen::Vector3d normal = (rotation * placement.up).normalized();
  Eigen::Vector3d u = rotation * placement.forward;
  u = (u - u.dot(normal) * normal);
  if (u.norm() < 1e-9) u = normal.unitOrthogonal();
  u.normalize();
  const Eigen::Vector3d v = normal.cross(u);
  // The shadow follows the pose: centred under the joints, as wide as they spread.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  double height = 0;
  for (const Eigen::Matrix4d& joint : frame.model) {
    const Eigen::Vector3d p = (model_to_map * joint.col(3)).head<3>() - origin;
    lo = lo.cwiseMin(Eigen::Vector2d(p.dot(u), p.dot(v)));
    hi = hi.cwiseMax(Eigen::Vector2d(p.dot(u), p.dot(v)));
    height = std::max(height, p.dot(normal));
  }
  if (frame.model.empty() || !(height > 0)) return false;
  const Eigen::Vector2d mid = (lo + hi) / 2;
  const Eigen::Vector2d radii = ((hi - lo) / 2).cwiseMax(0.15 * height) + Eigen::Vector2d::Constant(0.2 * height);
  *ellipse = {origin + mid.x() * u + mid.y() * v, u * radii.x(), v * radii.y()};
  return true;
}

cv::Rect ArRenderer::ScreenBounds(const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames,
                                  double* farthest) const {
  const cv::Rect full(0, 0, camera_.width, camera_.height);
  *farthest = std::numeric_limits<double>::infinity();
  if (options_.full_frame) return full;
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300, far_z = 0;
  bool behind = false;
  auto add = [&](const Eigen::Vector3d& world) {
    const Eigen::Vector3d c = eye.ToCamera(world);
    far_z = std::max(far_z, c.z());
    if (c.z() <= options_.clip.near_m) {
      behind = true;
      return;
    }
    const double u = pinhole_.fx * c.x() / c.z() + pinhole_.cx, v = pinhole_.fy * c.y() / c.z() + pinhole_.cy;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  };
  // A sphere's exact extent on screen: along each image axis, the two tangents from the eye.
  // (A cube around it, projected, is up to ~1.6x wider for a character close to the camera; the
  // rectangle's area is what 4x MSAA clears and resolves.)
  auto add_sphere = [&](const Eigen::Vector3d& world, double r) {
    const Eigen::Vector3d c = eye.ToCamera(world);
    far_z = std::max(far_z, c.z() + r);
    if (c.z() - r <= options_.clip.near_m) {
      behind = true;
      return;
    }
    const double zz = c.z() * c.z() - r * r;
    const double ru = r * std::sqrt(c.x() * c.x() + zz), rv = r * std::sqrt(c.y() * c.y() + zz);
    u0 = std::min(u0, pinhole_.fx * (c.x() * c.z() - ru) / zz + pinhole_.cx);
    u1 = std::max(u1, pinhole_.fx * (c.x() * c.z() + ru) / zz + pinhole_.cx);
    v0 = std::min(v0, pinhole_.fy * (c.y() * c.z() - rv) / zz + pinhole_.cy);
    v1 = std::max(v1, pinhole_.fy * (c.y() * c.z() + rv) / zz + pinhole_.cy);
  };
  for (size_t i = 0; i < characters_.size(); ++i) {
    const Placed& placed = characters_[i];
    const anim::AnimatorFrame& frame = *frames[i];
    const Eigen::Matrix4d model_to_map = placed.placement.ModelToMap();
    const std::span<const float> radii = placed.renderer->JointRadii(frame.morph_weights);
    for (size_t j = 0; j < frame.model.size() && j < radii.size(); ++j) {
      if (radii[j] <= 0) continue;
      // The joint's sphere of influence, enlarged 10% (DQS need not stay inside the linear
      // blend's hull) and by the joint's own scale.
      const Eigen::Matrix4d m = model_to_map * frame.model[j];
      const double scale = m.topLeftCorner<3, 3>().colwise().norm().maxCoeff();
      const double r = 1.1 * radii[j] * scale;
      const Eigen::Vector3d centre = m.col(3).head<3>();
      add_sphere(centre, r);
    }
    ShadowEllipse e;
    if (options_.shadow && Shadow(placed, frame, &e)) {
      for (int k = 0; k < 4; ++k) add(e.center + (k & 1 ? 1.0 : -1.0) * e.axis_u + (k & 2 ? 1.0 : -1.0) * e.axis_v);
    }
    if (behind) return full;
  }
  if (u0 > u1) return {};
  if (std::isfinite(far_z)) *farthest = far_z;
  // A pose or camera far outside the scene projects to huge or non-finite bounds: converting
  // those to int is undefined behaviour. Clamp to a margin around the image first.
  if (!std::isfinite(u0) || !std::isfinite(u1) || !std::isfinite(v0) || !std::isfinite(v1)) return full;
  const double limit = 4.0 * std::max(full.width, full.height) + 16;
  u0 = std::clamp(u0, -limit, limit);
  u1 = std::clamp(u1, -limit, limit);
  v0 = std::clamp(v0, -limit, limit);
  v1 = std::clamp(v1, -limit, limit);
  // Pixel centres are integers: a pixel is touched when its square reaches the bound.
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(u0)) - 2, static_cast<int>(std::floor(v0)) - 2),
                     cv::Point(static_cast<int>(std::ceil(u1)) + 3, static_cast<int>(std::ceil(v1)) + 3));
  return box & full;
}

void ArRenderer::Compose(cv::Mat& frame, const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames) {
  used_linear_fallback_ = false;
  double farthest = 0;
  const cv::Rect rect = ScreenBounds(eye, frames, &farthest);
  if (!rect.empty()) {
    DrawLayer(rect, eye, frames, farthest);
    if (pixel_buffer_readback_) target_.StartReadBgra();  // a GPU copies while the CPU darkens
  }
  // The cast shadows darken the camera image the layer goes over (the same as a premultiplied
  // shadow under the characters in the layer), on this thread while llvmpipe's rasterise the
  // layer's draws (or a GPU draws and copies them).
  for (const Placed& placed : characters_) {
    if (!placed.casts) continue;
    DarkenCastShadow(frame, pinhole_, eye, options_.clip.near_m, placed.light_view, placed.coverage,
                     CastShadowStrength(placed),
                     options_.occlusion ? std::span<const Eigen::Vector3f>(occluder_triangles_) : std::span<const Eigen::Vector3f>());
  }
  if (rect.empty()) return;  // no character in view: the video frame (and its shadows) as it is

  // OpenGL's row order: no flip's copy. A mapped pixel buffer is read in place.
  const cv::Mat layer = pixel_buffer_readback_ ? target_.MapBgraBottomUp() : target_.ReadBgraBottomUp();
  BlendPremultiplied(layer, rect, frame);
  if (pixel_buffer_readback_) target_.UnmapRead();
}

void ArRenderer::BlendPremultiplied(const cv::Mat& bottom_up_layer, const cv::Rect& rect, cv::Mat& frame) {
  // Premultiplied alpha over the video: out = fg + bg·(1 − a).
  for (int y = 0; y < rect.height; ++y) {
    const cv::Vec4b* fg = bottom_up_layer.ptr<cv::Vec4b>(rect.height - 1 - y);
    cv::Vec3b* bg = frame.ptr<cv::Vec3b>(rect.y + y) + rect.x;
    for (int x = 0; x < rect.width; ++x) {
      const int a = fg[x][3];
      if (a == 0) continue;
      const int keep = 255 - a;
      for (int c = 0; c < 3; ++c) bg[x][c] = cv::saturate_cast<uchar>(fg[x][c] + (bg[x][c] * keep + 127) / 255);
    }
  }
}

void ArRenderer::DrawLayer(const cv::Rect& rect, const calib::Pose& eye, std::span<const anim::AnimatorFrame* const> frames,
                           double farthest) {
  const GlApi& gl = context_->gl();
  auto character_draw = [&](const Placed& placed, const anim::AnimatorFrame& out) {
    const Eigen::Matrix3d rotation = placed.placement.Rotation();
    CharacterDraw draw;
    draw.model_to_map = placed.placement.ModelToMap();
    draw.skinning_matrices = out.skinning_matrices;
    draw.skinning_dual_quats = out.skinning_dual_quats;
    draw.morph_weights = out.morph_weights;
    draw.method = options_.skinning;
    draw.cull_back_faces = options_.cull_back_faces;
    // Key light from above and in front of the character, so that its face is lit and the
    // contact shadow straight below it is plausible.
    draw.light_direction_map =
        (rotation * (placed.placement.up.normalized() + 0.6 * placed.placement.forward.normalized())).normalized();
    draw.lighting = options_.lighting;
    draw.sh = current_sh_;
    return draw;
  };
  target_.Begin(rect);
  const Eigen::Matrix4d projection = ProjectionMatrix(pinhole_, options_.clip);
  const Eigen::Matrix4d view = ViewMatrix(eye);
  // Real things in front of the characters: depth only, before anything is drawn.
  if (options_.occlusion && occluders_) occluders_->Draw(projection, view, farthest);
  for (size_t i = 0; i < characters_.size(); ++i) {
    Placed& placed = characters_[i];
    const anim::AnimatorFrame& out = *frames[i];
    ShadowEllipse e;
    if (options_.shadow && Shadow(placed, out, &e)) {
      shadow_.Draw(projection, view, e.center, e.axis_u, e.axis_v, options_.shadow_strength);
    }
    placed.renderer->Draw(projection, view, character_draw(placed, out));
    used_linear_fallback_ = used_linear_fallback_ || placed.renderer->used_linear_fallback();
  }
  CheckGl(gl, "AR frame");
}

cv::Mat ArRenderer::Render(const cv::Mat& background, const calib::Pose& pose,
                           std::span<const anim::AnimatorFrame* const> frames) {
  FollowExposure(background, pose);
  UpdateCastShadows(frames);
  cv::Mat frame = PrepareBackground(background);
  Compose(frame, pose, frames);
  return frame;
}

void ArRenderer::WarmUp(const calib::Pose& pose, std::span<const anim::AnimatorFrame* const> frames) {
  target_.ReserveWholeImage();
  UpdateCastShadows(frames);
  cv::Mat frame = PrepareBackground(cv::Mat());
  Compose(frame, pose, frames);
  // Once more with every morph target barely weighted, for the meshes' morphing programs.
  std::vector<std::vector<float>> weights(frames.size());
  std::vector<anim::AnimatorFrame> morphed(frames.size());
  std::vector<const anim::AnimatorFrame*> morphed_ptrs(frames.size());
  bool any = false;
  for (size_t i = 0; i < frames.size(); ++i) {
    morphed[i] = *frames[i];
    weights[i].assign(frames[i]->morph_weights.size(), 1e-4f);
    if (!weights[i].empty()) morphed[i].morph_weights = weights[i];
    any = any || !weights[i].empty();
    morphed_ptrs[i] = &morphed[i];
  }
  if (any) Compose(frame, pose, morphed_ptrs);
}

cv::Mat ArRenderer::RenderSideBySide(const cv::Mat& background, const calib::Pose& pose,
                                     std::span<const anim::AnimatorFrame* const> frames, double ipd_m) {
  if (!(ipd_m >= 0 && ipd_m < 0.5)) throw RenderError("interpupillary distance must be in [0, 0.5) m");
  FollowExposure(background, pose);
  UpdateCastShadows(frames);
  const cv::Mat video = PrepareBackground(background);
  cv::Mat both(camera_.height, 2 * camera_.width, CV_8UC3);
  cv::Mat left = both(cv::Rect(0, 0, camera_.width, camera_.height));
  cv::Mat right = both(cv::Rect(camera_.width, 0, camera_.width, camera_.height));
  video.copyTo(left);
  video.copyTo(right);
  Compose(left, OffsetEye(pose, -ipd_m / 2), frames);
  Compose(right, OffsetEye(pose, ipd_m / 2), frames);
  return both;
}

}  // namespace arview::render
