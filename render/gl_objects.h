#pragma once
// Owning wrappers for the few kinds of OpenGL objects render/ uses, and the render target
// that every drawing goes into (multisampled colour + depth, resolved and read back as an
// OpenCV image with row 0 at the top).

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_api.h"

namespace arview::render {

// A move-only GL name with its deleter.
class GlName {
 public:
  using Deleter = void (*)(const GlApi&, GLuint);
  GlName() = default;
  GlName(const GlApi* gl, GLuint name, Deleter deleter) : gl_(gl), name_(name), deleter_(deleter) {}
  GlName(GlName&& other) noexcept { *this = std::move(other); }
  GlName& operator=(GlName&& other) noexcept {
    if (this != &other) {
      Reset();
      std::swap(gl_, other.gl_);
      std::swap(name_, other.name_);
      std::swap(deleter_, other.deleter_);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  ~GlName() { Reset(); }
  GLuint get() const { return name_; }
  void Reset() {
    if (gl_ != nullptr && name_ != 0) deleter_(*gl_, name_);
    gl_ = nullptr;
    name_ = 0;
  }

 private:
  const GlApi* gl_ = nullptr;
  GLuint name_ = 0;
  Deleter deleter_ = nullptr;
};

// Compiles and links; throws RenderError with the driver's log naming `label`.
GlName MakeProgram(const GlApi& gl, const std::string& label, const std::string& vertex_source,
                   const std::string& fragment_source);
GLint Uniform(const GlApi& gl, GLuint program, const char* name);  // -1 when optimised out

struct TextureOptions {
  bool mipmaps = true;
  float anisotropy = 8.f;  // GL_TEXTURE_MAX_ANISOTROPY (core in 4.6, EXT on 4.5; llvmpipe has 16)
  bool repeat = false;
};
// An 8-bit BGR, BGRA or grey cv::Mat as an sRGB-agnostic RGBA texture. Row 0 of the image is
// uploaded first, so texture coordinate v = 0 is the image's top row.
GlName MakeTexture(const GlApi& gl, const cv::Mat& image, const TextureOptions& options = {});
// Replaces the contents of a texture made by MakeTexture with an image of the same size.
void UpdateTexture(const GlApi& gl, GLuint texture, const cv::Mat& image);

GlName MakeBuffer(const GlApi& gl, GLenum target, const void* data, size_t bytes, GLenum usage = GL_STATIC_DRAW);
GlName MakeVertexArray(const GlApi& gl);
// A buffer texture (GL_TEXTURE_BUFFER) reading `buffer` as texels of `format` (e.g. GL_RGB32F).
GlName MakeBufferTexture(const GlApi& gl, GLuint buffer, GLenum format);

// A read-back through a pixel-buffer object: Start asks the GL to copy a rectangle into the
// buffer and sets a fence, and returns at once on a GPU (the copy runs while the CPU does other
// work); Map waits for the fence and maps the buffer. glReadPixels into client memory instead
// makes the CPU wait for every queued draw and then for the copy: on a GPU that stall is the
// read-back's cost. On llvmpipe the copy is done by the CPU inside Start either way.
class PixelReadback {
 public:
  explicit PixelReadback(const GlApi& gl) : gl_(&gl) {}
  PixelReadback(const PixelReadback&) = delete;
  PixelReadback& operator=(const PixelReadback&) = delete;
  ~PixelReadback();
  // Reads `gl_rect` (OpenGL's coordinates: rows from the bottom) of the bound read framebuffer.
  void Start(const cv::Rect& gl_rect, GLenum format, int channels);
  // The pixels Start asked for, row 0 at the bottom; valid until Unmap (or the next Start).
  cv::Mat Map();
  void Unmap();

 private:
  const GlApi* gl_;
  GlName buffer_;
  size_t capacity_ = 0;
  GLsync fence_ = nullptr;
  cv::Size size_;
  int type_ = 0;
  bool mapped_ = false;
};

// Keeps llvmpipe's scene fences alive until a later scene's fence has signalled, as GL sync
// objects (each holds a reference to the fence of the newest scene when it was made).
// Why: Mesa 22.3's llvmpipe may free a scene's fence while the rasterizer thread that signalled
// it has not yet unlocked the fence's mutex (the drawing thread reads the fence's count without
// that lock, in lp_setup_get_empty_scene and fence_finish, and then drops its references), and
// that unlock writes into freed memory: issue 57's live crash (docs/reliability.md, "The live
// crash"). A fence whose last reference is one of these goes only after a later fence
// signalled, when every rasterizer thread has let it go. One per context (OffscreenContext,
// GlApi::scene_fences), so that the newest fence stays held after its target is gone.
// Test: gl_fence_tests.
class SceneFences {
 public:
  enum class Lifetime {
    kDeletedHere,         // the destructor deletes what it holds (the context must be current)
    kFreedWithTheContext  // the GL context, destroyed first, frees them
  };
  SceneFences(const GlApi& gl, Lifetime lifetime) : gl_(&gl), lifetime_(lifetime) {}
  SceneFences(const SceneFences&) = delete;
  SceneFences& operator=(const SceneFences&) = delete;
  ~SceneFences();
  // Hands the scene drawn so far to the rasterizer and holds the newest scene's fence.
  void HoldCurrent();
  // After a read-back returned (the newest fence signalled): lets go of all but the newest.
  void ReleaseOlder();

 private:
  const GlApi* gl_;
  Lifetime lifetime_;
  std::vector<GLsync> held_;
};

// The fences `gl`'s read-backs hold: its context's, else a new set of their own.
std::shared_ptr<SceneFences> FencesFor(const GlApi& gl);

// A framebuffer to draw into: colour RGBA8 + depth 24, multisampled when samples > 1 and
// resolved on read-back. Its read-backs hold the scenes' fences (SceneFences: the context's, or
// `fences` where the GlApi has none).
class RenderTarget {
 public:
  RenderTarget(const GlApi& gl, int width, int height, int samples, std::shared_ptr<SceneFences> fences = nullptr);
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }
  // Binds the drawing framebuffer and sets the viewport.
  void Bind() const;
  // Resolves and reads back. Row 0 of the result is the top row of the image (OpenGL's
  // bottom-up rows are flipped here, the one place that does so).
  cv::Mat ReadBgr() const;   // CV_8UC3
  cv::Mat ReadBgra() const;  // CV_8UC4, alpha = coverage
  // Only `rect` (image coordinates, row 0 at the top; clipped to the target), resolving only
  // that part: the cost of multisampling then scales with the area drawn.
  cv::Mat ReadBgra(const cv::Rect& rect) const;
  // The same in OpenGL's row order (row 0 at the bottom), without the flip's copy: for a
  // caller that walks the rows anyway (the compositing, on the render stage's critical path).
  cv::Mat ReadBgraBottomUp(const cv::Rect& rect) const;
  // The same through a pixel-buffer object (PixelReadback): resolves `rect` and starts its copy,
  // which `readback.Map()` then returns (row 0 at the bottom).
  void StartReadBgra(const cv::Rect& rect, PixelReadback& readback) const;
  // Limits clears and drawing to `rect` (image coordinates); an empty rect disables the limit.
  void Scissor(const cv::Rect& rect) const;

 private:
  cv::Mat Read(GLenum format, int channels, cv::Rect rect, bool top_down = true) const;
  // Resolves the multisampled rectangle (OpenGL's coordinates) and binds what holds it for reading.
  void BindResolved(const cv::Rect& gl_rect) const;
  // `rect` (rows from the top) clipped to the target, in OpenGL's coordinates.
  cv::Rect GlRect(cv::Rect rect) const;
  const GlApi* gl_;
  int width_, height_, samples_;
  GlName draw_fbo_, color_rb_, depth_rb_;
  GlName resolve_fbo_, resolve_rb_;
  std::shared_ptr<SceneFences> fences_;
};

// Draws one rectangle of a larger image into a target about the rectangle's size: the viewport
// is the whole image's, offset by the rectangle's corner, so the image's pixels inside the
// rectangle land in the target exactly where a full-image target would have them (an integer
// shift: the same rasterisation). Why: llvmpipe clears a whole target with its fast path (a fill
// per 64-pixel tile), while a scissored clear is drawn as a quad at every sample; for the
// character's rectangle at 4x MSAA that was ~1 ms of the frame (docs/render.md).
// The target is sized up to whole 64-pixel tiles with a quarter more on each side, and kept while
// rectangles fit in it; it is made again for a rectangle that does not fit, or after
// 30 rectangles in a row that each had less than half its area. Making a
// target costs 1-46 ms on llvmpipe (its memory is touched anew; the room's lap at 640x480, 4x
// MSAA): made for every other size, as before, it was the render thread's longest frames.
class RegionTarget {
 public:
  RegionTarget(const GlApi& gl, cv::Size image, int samples);
  // Binds a target for `rect` (image coordinates, row 0 at the top; clipped to the image),
  // clears it (colour 0, depth 1) and limits drawing to the rectangle. Empty rect: nothing bound.
  void Begin(const cv::Rect& rect);
  // Makes the target the whole image's size now (a warm-up), so that the first rectangles do not
  // make it again; it shrinks as any target does.
  void ReserveWholeImage();
  // The rectangle of the last Begin, resolved and read back (CV_8UC4, row 0 at the top); the
  // scissor test is off again.
  cv::Mat ReadBgra() const;
  cv::Mat ReadBgraBottomUp() const;  // the same, row 0 at the bottom (RenderTarget::ReadBgraBottomUp)
  // The same through a pixel-buffer object: StartReadBgra, other work, then MapBgraBottomUp,
  // whose image stays valid until UnmapRead.
  void StartReadBgra();
  cv::Mat MapBgraBottomUp();
  void UnmapRead();
  cv::Size target_size() const { return target_ ? cv::Size(target_->width(), target_->height()) : cv::Size(); }

 private:
  // Where the rectangle lies in the target (its rows from the target's top, as RenderTarget counts).
  cv::Rect TargetRect() const;
  const GlApi* gl_;
  cv::Size image_;
  int samples_;
  cv::Rect rect_;
  cv::Point origin_;    // the target's pixel (0, 0) in the image, OpenGL's rows (from the bottom)
  cv::Rect in_target_;  // rect_ in the target, OpenGL's rows
  std::shared_ptr<SceneFences> fences_;  // outlives the targets it replaces
  std::unique_ptr<RenderTarget> target_;
  std::unique_ptr<PixelReadback> readback_;
  int small_in_a_row_ = 0;  // rectangles in a row with under half the target's area
};

}  // namespace arview::render
