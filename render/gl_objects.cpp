#include "render/gl_objects.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <vector>

#include "render/offscreen.h"
#include "render/scene_fence_policy.h"

namespace arview::render {
namespace {

// GL_TEXTURE_MAX_ANISOTROPY: core since 4.6, same value as the EXT token llvmpipe exposes.
constexpr GLenum kMaxAnisotropy = 0x84FE;
constexpr GLenum kMaxAnisotropyLimit = 0x84FF;

GlName CompileShader(const GlApi& gl, GLenum type, const std::string& source, const std::string& label) {
  GlName shader(&gl, gl.CreateShader(type), [](const GlApi& g, GLuint n) { g.DeleteShader(n); });
  const char* text = source.c_str();
  gl.ShaderSource(shader.get(), 1, &text, nullptr);
  gl.CompileShader(shader.get());
  GLint ok = 0;
  gl.GetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {0};
    gl.GetShaderInfoLog(shader.get(), sizeof log, nullptr, log);
    throw RenderError(label + (type == GL_VERTEX_SHADER ? " vertex" : " fragment") +
                      " shader does not compile: " + log);
  }
  return shader;
}

}  // namespace

GlName MakeProgram(const GlApi& gl, const std::string& label, const std::string& vertex_source,
                   const std::string& fragment_source) {
  GlName vs = CompileShader(gl, GL_VERTEX_SHADER, vertex_source, label);
  GlName fs = CompileShader(gl, GL_FRAGMENT_SHADER, fragment_source, label);
  GlName program(&gl, gl.CreateProgram(), [](const GlApi& g, GLuint n) { g.DeleteProgram(n); });
  gl.AttachShader(program.get(), vs.get());
  gl.AttachShader(program.get(), fs.get());
  gl.LinkProgram(program.get());
  GLint ok = 0;
  gl.GetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {0};
    gl.GetProgramInfoLog(program.get(), sizeof log, nullptr, log);
    throw RenderError(label + " program does not link: " + log);
  }
  return program;
}

GLint Uniform(const GlApi& gl, GLuint program, const char* name) { return gl.GetUniformLocation(program, name); }

namespace {

cv::Mat ToRgba(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U) throw RenderError("texture image must be a non-empty 8-bit image");
  cv::Mat rgba;
  switch (image.channels()) {
    case 1: cv::cvtColor(image, rgba, cv::COLOR_GRAY2RGBA); break;
    case 3: cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA); break;
    case 4: cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA); break;
    default: throw RenderError("texture image must have 1, 3 or 4 channels");
  }
  return rgba;
}

}  // namespace

GlName MakeTexture(const GlApi& gl, const cv::Mat& image, const TextureOptions& options) {
  const cv::Mat rgba = ToRgba(image);
  GLuint name = 0;
  gl.GenTextures(1, &name);
  GlName texture(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteTextures(1, &n); });
  gl.BindTexture(GL_TEXTURE_2D, name);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(rgba.step / 4));
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.cols, rgba.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  const GLint wrap = options.repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  if (options.mipmaps) {
    gl.GenerateMipmap(GL_TEXTURE_2D);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    if (options.anisotropy > 1.f) {
      GLfloat limit = 1.f;
      gl.GetFloatv(kMaxAnisotropyLimit, &limit);
      gl.TexParameterf(GL_TEXTURE_2D, kMaxAnisotropy, std::min(options.anisotropy, limit));
    }
  } else {
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  }
  CheckGl(gl, "texture upload");
  return texture;
}

void UpdateTexture(const GlApi& gl, GLuint texture, const cv::Mat& image) {
  const cv::Mat rgba = ToRgba(image);
  gl.BindTexture(GL_TEXTURE_2D, texture);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(rgba.step / 4));
  gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, rgba.cols, rgba.rows, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  CheckGl(gl, "texture update");
}

GlName MakeBuffer(const GlApi& gl, GLenum target, const void* data, size_t bytes, GLenum usage) {
  GLuint name = 0;
  gl.GenBuffers(1, &name);
  GlName buffer(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteBuffers(1, &n); });
  gl.BindBuffer(target, name);
  gl.BufferData(target, static_cast<GLsizeiptr>(bytes), data, usage);
  return buffer;
}

GlName MakeBufferTexture(const GlApi& gl, GLuint buffer, GLenum format) {
  GLuint name = 0;
  gl.GenTextures(1, &name);
  GlName texture(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteTextures(1, &n); });
  gl.BindTexture(GL_TEXTURE_BUFFER, name);
  gl.TexBuffer(GL_TEXTURE_BUFFER, format, buffer);
  gl.BindTexture(GL_TEXTURE_BUFFER, 0);
  return texture;
}

GlName MakeVertexArray(const GlApi& gl) {
  GLuint name = 0;
  gl.GenVertexArrays(1, &name);
  return GlName(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteVertexArrays(1, &n); });
}

namespace {

GlName MakeRenderbuffer(const GlApi& gl, GLenum format, int width, int height, int samples) {
  GLuint name = 0;
  gl.GenRenderbuffers(1, &name);
  GlName rb(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteRenderbuffers(1, &n); });
  gl.BindRenderbuffer(GL_RENDERBUFFER, name);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, format, width, height);
  return rb;
}

GlName MakeFramebuffer(const GlApi& gl) {
  GLuint name = 0;
  gl.GenFramebuffers(1, &name);
  return GlName(&gl, name, [](const GlApi& g, GLuint n) { g.DeleteFramebuffers(1, &n); });
}

void RequireComplete(const GlApi& gl, const std::string& what) {
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError(what + " framebuffer is incomplete (status " + std::to_string(status) + ")");
  }
}

std::atomic<SceneFencePolicy> g_fence_policy{SceneFencePolicy::kHold};

}  // namespace

void SetSceneFencePolicyForTiming(SceneFencePolicy policy) { g_fence_policy.store(policy); }

SceneFences::~SceneFences() {
  if (lifetime_ == Lifetime::kFreedWithTheContext) return;
  for (GLsync fence : held_) gl_->DeleteSync(fence);
}

void SceneFences::HoldCurrent() {
  const SceneFencePolicy policy = g_fence_policy.load(std::memory_order_relaxed);
  if (policy == SceneFencePolicy::kNone) return;
  // glFenceSync hands the scene drawn so far to the rasterizer and references llvmpipe's fence
  // of the newest scene (its last_fence, when nothing new was drawn) until glDeleteSync.
  GLsync fence = gl_->FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  if (policy == SceneFencePolicy::kReleaseAtOnce) {
    gl_->DeleteSync(fence);
    return;
  }
  held_.push_back(fence);
}

void SceneFences::ReleaseOlder() {
  // The newest fence has signalled: every rasterizer thread signalled the older ones before it
  // (scenes are rasterized in order) and has let their mutexes go.
  while (held_.size() > 1) {
    gl_->DeleteSync(held_.front());
    held_.erase(held_.begin());
  }
}

std::shared_ptr<SceneFences> FencesFor(const GlApi& gl) {
  if (gl.scene_fences != nullptr) return std::shared_ptr<SceneFences>(gl.scene_fences, [](SceneFences*) {});
  return std::make_shared<SceneFences>(gl, SceneFences::Lifetime::kDeletedHere);
}

RenderTarget::RenderTarget(const GlApi& gl, int width, int height, int samples, std::shared_ptr<SceneFences> fences)
    : gl_(&gl), width_(width), height_(height), samples_(samples), fences_(fences ? std::move(fences) : FencesFor(gl)) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw RenderError("render target size " + std::to_string(width) + "x" + std::to_string(height) +
                      " is not usable");
  }
  GLint max_samples = 0;
  gl.GetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (samples < 0 || samples > max_samples) {
    throw RenderError(std::to_string(samples) + " samples requested; this OpenGL offers at most " +
                      std::to_string(max_samples));
  }
  draw_fbo_ = MakeFramebuffer(gl);
  color_rb_ = MakeRenderbuffer(gl, GL_RGBA8, width, height, samples);
  depth_rb_ = MakeRenderbuffer(gl, GL_DEPTH_COMPONENT24, width, height, samples);
  gl.BindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.get());
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb_.get());
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb_.get());
  RequireComplete(gl, "drawing");
  if (samples > 1) {
    resolve_fbo_ = MakeFramebuffer(gl);
    resolve_rb_ = MakeRenderbuffer(gl, GL_RGBA8, width, height, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_.get());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rb_.get());
    RequireComplete(gl, "resolve");
  }
  CheckGl(gl, "render target creation");
}

void RenderTarget::Bind() const {
  gl_->BindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.get());
  gl_->Viewport(0, 0, width_, height_);
}

cv::Rect RenderTarget::GlRect(cv::Rect rect) const {
  rect &= cv::Rect(0, 0, width_, height_);
  return {rect.x, height_ - rect.y - rect.height, rect.width, rect.height};  // OpenGL counts rows from the bottom
}

void RenderTarget::BindResolved(const cv::Rect& r) const {
  const GlApi& gl = *gl_;
  GLuint source = draw_fbo_.get();
  if (samples_ > 1) {
    fences_->HoldCurrent();  // the drawing's scene, whose fence the resolve's scene may free (SceneFences)
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_.get());
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_.get());
    gl.Disable(GL_SCISSOR_TEST);
    gl.BlitFramebuffer(r.x, r.y, r.x + r.width, r.y + r.height, r.x, r.y, r.x + r.width, r.y + r.height,
                       GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = resolve_fbo_.get();
  }
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, source);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
}

cv::Mat RenderTarget::Read(GLenum format, int channels, cv::Rect rect, bool top_down) const {
  const GlApi& gl = *gl_;
  const cv::Rect r = GlRect(rect);
  if (r.empty()) return cv::Mat(0, 0, CV_8UC(channels));
  BindResolved(r);
  cv::Mat bottom_up(r.height, r.width, CV_8UC(channels));
  gl.ReadPixels(r.x, r.y, r.width, r.height, format, GL_UNSIGNED_BYTE, bottom_up.data);
  fences_->HoldCurrent();  // the read scene's fence, signalled now
  fences_->ReleaseOlder();
  CheckGl(gl, "read-back");
  if (!top_down) return bottom_up;
  cv::Mat image;
  cv::flip(bottom_up, image, 0);
  return image;
}

void RenderTarget::StartReadBgra(const cv::Rect& rect, PixelReadback& readback) const {
  const cv::Rect r = GlRect(rect);
  if (!r.empty()) BindResolved(r);
  readback.Start(r, GL_BGRA, 4);
  // On llvmpipe the copy into the buffer is done inside Start: the read scene's fence has
  // signalled (on a GPU the driver's own fences need none of this).
  fences_->HoldCurrent();
  fences_->ReleaseOlder();
}

PixelReadback::~PixelReadback() {
  if (mapped_) Unmap();
  if (fence_ != nullptr) gl_->DeleteSync(fence_);
}

void PixelReadback::Start(const cv::Rect& gl_rect, GLenum format, int channels) {
  const GlApi& gl = *gl_;
  if (mapped_) Unmap();
  if (fence_ != nullptr) gl.DeleteSync(fence_);
  fence_ = nullptr;
  size_ = gl_rect.size();
  type_ = CV_8UC(channels);
  if (gl_rect.empty()) return;
  const size_t bytes = static_cast<size_t>(gl_rect.area()) * channels;
  if (bytes > capacity_) {
    // GL_STREAM_READ: written by the GL once, read by the CPU once.
    buffer_ = MakeBuffer(gl, GL_PIXEL_PACK_BUFFER, nullptr, bytes, GL_STREAM_READ);
    capacity_ = bytes;
  }
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, buffer_.get());
  gl.ReadPixels(gl_rect.x, gl_rect.y, gl_rect.width, gl_rect.height, format, GL_UNSIGNED_BYTE, nullptr);
  fence_ = gl.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  CheckGl(gl, "read-back into a pixel buffer");
}

cv::Mat PixelReadback::Map() {
  const GlApi& gl = *gl_;
  if (size_.empty()) return cv::Mat(0, 0, type_);
  if (fence_ == nullptr) throw RenderError("pixel buffer mapped without a read started");
  // Flush the fence with the first wait; a second is never needed, the wait is unbounded.
  const GLenum waited = gl.ClientWaitSync(fence_, GL_SYNC_FLUSH_COMMANDS_BIT, GL_TIMEOUT_IGNORED);
  if (waited == GL_WAIT_FAILED) throw RenderError("waiting for the pixel buffer's read-back failed");
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, buffer_.get());
  void* pixels = gl.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(size_.area()) * CV_ELEM_SIZE(type_),
                                   GL_MAP_READ_BIT);
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  if (pixels == nullptr) {
    CheckGl(gl, "mapping the pixel buffer");
    throw RenderError("the pixel buffer could not be mapped");
  }
  mapped_ = true;
  return cv::Mat(size_, type_, pixels);
}

void PixelReadback::Unmap() {
  if (!mapped_) return;
  const GlApi& gl = *gl_;
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, buffer_.get());
  gl.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  mapped_ = false;
}

cv::Mat RenderTarget::ReadBgr() const { return Read(GL_BGR, 3, {0, 0, width_, height_}); }
cv::Mat RenderTarget::ReadBgra() const { return Read(GL_BGRA, 4, {0, 0, width_, height_}); }
cv::Mat RenderTarget::ReadBgra(const cv::Rect& rect) const { return Read(GL_BGRA, 4, rect); }
cv::Mat RenderTarget::ReadBgraBottomUp(const cv::Rect& rect) const { return Read(GL_BGRA, 4, rect, false); }

void RenderTarget::Scissor(const cv::Rect& rect) const {
  if (rect.empty()) {
    gl_->Disable(GL_SCISSOR_TEST);
    return;
  }
  gl_->Enable(GL_SCISSOR_TEST);
  gl_->Scissor(rect.x, height_ - rect.y - rect.height, rect.width, rect.height);
}

namespace {

// llvmpipe bins and clears in tiles of 64 x 64 pixels.
constexpr int kTile = 64;
// RegionTarget's frames with a small rectangle before its target is made smaller (1 s at 30 fps).
constexpr int kShrinkAfterFrames = 30;
int RoundUpToTile(int pixels) { return (pixels + kTile - 1) / kTile * kTile; }

}  // namespace

RegionTarget::RegionTarget(const GlApi& gl, cv::Size image, int samples)
    : gl_(&gl), image_(image), samples_(samples), fences_(FencesFor(gl)) {
  RenderTarget(gl, image.width, image.height, samples);  // validates the size and the sample count once
}

void RegionTarget::Begin(const cv::Rect& rect) {
  rect_ = rect & cv::Rect(cv::Point(0, 0), image_);
  if (rect_.empty()) return;
  // OpenGL counts rows from the bottom. The target's corner is put on the image's 64-pixel grid:
  // shifted by whole tiles, llvmpipe rasterises the same samples and interpolates within a unit
  // of the full-image render (test FoxTest.BoundedRenderEqualsFullFrameRender); with a shift of
  // any number of pixels a few edge pixels moved by up to 3 levels.
  const int bottom = image_.height - rect_.y - rect_.height;
  origin_ = cv::Point(rect_.x / kTile * kTile, bottom / kTile * kTile);
  in_target_ = cv::Rect(rect_.x - origin_.x, bottom - origin_.y, rect_.width, rect_.height);
  const cv::Size needed(std::min(RoundUpToTile(in_target_.x + in_target_.width), image_.width - origin_.x),
                        std::min(RoundUpToTile(in_target_.y + in_target_.height), image_.height - origin_.y));
  const cv::Size have = target_size();
  const bool fits = needed.width <= have.width && needed.height <= have.height;
  small_in_a_row_ = fits && 2 * needed.area() < have.area() ? small_in_a_row_ + 1 : 0;
  if (!fits || small_in_a_row_ > kShrinkAfterFrames) {
    // Room to grow: a character walking closer needs a larger rectangle every few frames.
    // Growing keeps the other side's room; the image's own size always suffices.
    const int width = std::max(RoundUpToTile(needed.width * 5 / 4), fits ? 0 : have.width);
    const int height = std::max(RoundUpToTile(needed.height * 5 / 4), fits ? 0 : have.height);
    target_ = std::make_unique<RenderTarget>(*gl_, std::min(width, image_.width), std::min(height, image_.height), samples_,
                                             fences_);
    small_in_a_row_ = 0;
  }
  const GlApi& gl = *gl_;
  target_->Bind();
  gl.Viewport(-origin_.x, -origin_.y, image_.width, image_.height);
  target_->Scissor({});
  gl.ClearColor(0, 0, 0, 0);
  gl.ClearDepth(1.0);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  target_->Scissor(TargetRect());
}

void RegionTarget::ReserveWholeImage() {
  target_ = std::make_unique<RenderTarget>(*gl_, image_.width, image_.height, samples_, fences_);
  small_in_a_row_ = 0;
  Begin(cv::Rect(cv::Point(0, 0), image_));  // its memory touched by a clear
  rect_ = {};
}

cv::Rect RegionTarget::TargetRect() const {
  // RenderTarget counts rows from the top.
  return {in_target_.x, target_->height() - in_target_.y - in_target_.height, in_target_.width, in_target_.height};
}

cv::Mat RegionTarget::ReadBgra() const {
  if (rect_.empty() || !target_) return cv::Mat(0, 0, CV_8UC4);
  target_->Scissor({});  // drawing into the region is over
  return target_->ReadBgra(TargetRect());
}

cv::Mat RegionTarget::ReadBgraBottomUp() const {
  if (rect_.empty() || !target_) return cv::Mat(0, 0, CV_8UC4);
  target_->Scissor({});
  return target_->ReadBgraBottomUp(TargetRect());
}

void RegionTarget::StartReadBgra() {
  if (!readback_) readback_ = std::make_unique<PixelReadback>(*gl_);
  if (rect_.empty() || !target_) {
    readback_->Start({}, GL_BGRA, 4);
    return;
  }
  target_->Scissor({});
  target_->StartReadBgra(TargetRect(), *readback_);
}

cv::Mat RegionTarget::MapBgraBottomUp() {
  if (!readback_) throw RenderError("region mapped without a read started");
  return readback_->Map();
}

void RegionTarget::UnmapRead() {
  if (readback_) readback_->Unmap();
}

}  // namespace arview::render
