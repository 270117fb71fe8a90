#include "render/ar_renderer.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace arview::render {
namespace {

// A full-screen triangle sampling the background so that texel centres fall on pixel centres.
const char* kBackgroundVertex = R"(#version 450 core
out vec2 v_uv;
void main() {
  vec2 ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  v_uv = vec2((ndc.x + 1.0) * 0.5, (1.0 - ndc.y) * 0.5);  // row 0 of the image at the top
  gl_Position = vec4(ndc, 1.0, 1.0);
}
)";

const char* kBackgroundFragment = R"(#version 450 core
in vec2 v_uv;
uniform sampler2D image;
out vec4 frag_color;
void main() { frag_color = vec4(texture(image, v_uv).rgb, 1.0); }
)";

}  // namespace

ArRenderer::ArRenderer(OffscreenContext& context, const calib::Camera& camera, const ArOptions& options)
    : context_(&context),
      camera_(camera),
      pinhole_(camera.WithoutDistortion()),
      options_(options),
      target_(context.gl(), camera.width, camera.height, options.samples > 1 ? options.samples : 0),
      shadow_(context.gl()) {
  const GlApi& gl = context.gl();
  ProjectionMatrix(pinhole_, options_.clip);  // validates the camera and the clip range
  if (camera_.HasDistortion()) {
    cv::initUndistortRectifyMap(camera_.K(), camera_.DistCoeffs(), cv::noArray(), camera_.K(), camera_.Size(),
                                CV_16SC2, undistort_map1_, undistort_map2_);
  }
  background_program_ = MakeProgram(gl, "background", kBackgroundVertex, kBackgroundFragment);
  background_vao_ = MakeVertexArray(gl);
  background_texture_ = MakeTexture(gl, cv::Mat(camera.height, camera.width, CV_8UC3, cv::Scalar::all(0)),
                                    {false, 1.f, false});
}

int ArRenderer::AddCharacter(const anim::Character& character, const anim::CharacterSpec& spec) {
  characters_.push_back({&character, &spec, std::make_unique<CharacterRenderer>(context_->gl(), character)});
  return static_cast<int>(characters_.size()) - 1;
}

void ArRenderer::PrepareBackground(const cv::Mat& background) {
  has_background_ = !background.empty();
  if (!has_background_) return;
  if (background.size() != camera_.Size() || background.depth() != CV_8U ||
      (background.channels() != 1 && background.channels() != 3)) {
    throw RenderError("background image is " + std::to_string(background.cols) + "x" +
                      std::to_string(background.rows) + " with " + std::to_string(background.channels()) +
                      " channels; the camera is " + std::to_string(camera_.width) + "x" +
                      std::to_string(camera_.height) + " (8-bit BGR or grey expected)");
  }
  const cv::Mat* image = &background;
  if (camera_.HasDistortion()) {
    cv::remap(background, undistorted_, undistort_map1_, undistort_map2_, cv::INTER_LINEAR);
    image = &undistorted_;
  }
  const GlApi& gl = context_->gl();
  gl.BindTexture(GL_TEXTURE_2D, background_texture_.get());
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(image->step / image->elemSize()));
  // BGR and grey go up as they are: no conversion on the CPU.
  gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image->cols, image->rows, image->channels() == 3 ? GL_BGR : GL_RED,
                   GL_UNSIGNED_BYTE, image->data);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  if (image->channels() == 1) {
    const GLint swizzle[] = {GL_RED, GL_RED, GL_RED};
    for (int i = 0; i < 3; ++i) gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_R + i, swizzle[i]);
  } else {
    for (int i = 0; i < 3; ++i) gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_R + i, GL_RED + i);
  }
}

void ArRenderer::DrawShadow(const Placed& placed, const anim::FrameOutput& frame, const Eigen::Matrix4d& projection,
                            const Eigen::Matrix4d& view) {
  const anim::CharacterSpec& spec = *placed.spec;
  const Eigen::Matrix4d model_to_map = spec.ModelToMap();
  const Eigen::Matrix3d rotation = spec.anchor.rotation.normalized().toRotationMatrix();
  const Eigen::Vector3d origin = spec.anchor.position;
  const Eigen::Vector3d normal = (rotation * spec.up).normalized();
  Eigen::Vector3d u = rotation * spec.forward;
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
  if (frame.model.empty() || !(height > 0)) return;
  const Eigen::Vector2d mid = (lo + hi) / 2;
  const Eigen::Vector2d radii = ((hi - lo) / 2).cwiseMax(0.15 * height) + Eigen::Vector2d::Constant(0.2 * height);
  shadow_.Draw(projection, view, origin + mid.x() * u + mid.y() * v, u * radii.x(), v * radii.y(),
               options_.shadow_strength);
}

void ArRenderer::Draw(const calib::Pose& eye, std::span<const anim::FrameOutput* const> frames) {
  if (frames.size() != characters_.size()) {
    throw RenderError("AR render: " + std::to_string(characters_.size()) + " characters but " +
                      std::to_string(frames.size()) + " animation frames");
  }
  const GlApi& gl = context_->gl();
  target_.Bind();
  const cv::Scalar& grey = options_.empty_background;
  gl.ClearColor(float(grey[2] / 255), float(grey[1] / 255), float(grey[0] / 255), 1.f);
  gl.ClearDepth(1.0);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (has_background_) {
    gl.Disable(GL_DEPTH_TEST);
    gl.DepthMask(GL_FALSE);
    gl.UseProgram(background_program_.get());
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, background_texture_.get());
    gl.BindVertexArray(background_vao_.get());
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.DepthMask(GL_TRUE);
  }
  const Eigen::Matrix4d projection = ProjectionMatrix(pinhole_, options_.clip);
  const Eigen::Matrix4d view = ViewMatrix(eye);
  used_linear_fallback_ = false;
  for (size_t i = 0; i < characters_.size(); ++i) {
    Placed& placed = characters_[i];
    const anim::FrameOutput& frame = *frames[i];
    if (options_.shadow) DrawShadow(placed, frame, projection, view);
    const Eigen::Matrix3d rotation = placed.spec->anchor.rotation.normalized().toRotationMatrix();
    CharacterDraw draw;
    draw.model_to_map = placed.spec->ModelToMap();
    draw.skinning_matrices = frame.skinning_matrices;
    draw.skinning_dual_quats = frame.skinning_dual_quats;
    draw.method = options_.skinning;
    // Key light from above and in front of the character, so that its face is lit and the
    // contact shadow straight below it is plausible.
    draw.light_direction_map = (rotation * (placed.spec->up.normalized() + 0.6 * placed.spec->forward.normalized())).normalized();
    placed.renderer->Draw(projection, view, draw);
    used_linear_fallback_ = used_linear_fallback_ || placed.renderer->used_linear_fallback();
  }
  CheckGl(gl, "AR frame");
}

cv::Mat ArRenderer::Render(const cv::Mat& background, const calib::Pose& pose,
                           std::span<const anim::FrameOutput* const> frames) {
  PrepareBackground(background);
  Draw(pose, frames);
  return target_.ReadBgr();
}

cv::Mat ArRenderer::RenderSideBySide(const cv::Mat& background, const calib::Pose& pose,
                                     std::span<const anim::FrameOutput* const> frames, double ipd_m) {
  if (!(ipd_m >= 0 && ipd_m < 0.5)) throw RenderError("interpupillary distance must be in [0, 0.5) m");
  PrepareBackground(background);
  cv::Mat both(camera_.height, 2 * camera_.width, CV_8UC3);
  Draw(OffsetEye(pose, -ipd_m / 2), frames);
  target_.ReadBgr().copyTo(both(cv::Rect(0, 0, camera_.width, camera_.height)));
  Draw(OffsetEye(pose, ipd_m / 2), frames);
  target_.ReadBgr().copyTo(both(cv::Rect(camera_.width, 0, camera_.width, camera_.height)));
  return both;
}

}  // namespace arview::render
